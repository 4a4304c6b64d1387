"""Headless tests of the Rubble Fracture add-on (env: RUBBLE_PYTHON_DIR, RUBBLE_CLI; exit code 1 on failure).

blender -b --factory-startup --python tests/blender/test_addon.py
    Registers the add-on, fractures a subdivided cube and a closed Suzanne at the 3D cursor and checks: at least
    two pieces, summed bmesh volume = the input's to 1e-6 relative, the interior material on cut faces; an open
    Suzanne is refused with a report and left untouched; rigid bodies with convex hull shapes; the batch export
    writes -convcolonly children; the Surface presets and Set roughness make rough cuts that keep the volume; a `rubble fracture --depth 2 --format gltf` file imports with its collision
    children.
xvfb-run -a blender --factory-startup --python tests/blender/test_addon.py
    The same with a window (Blender's undo needs one: in -b, ed.undo's poll fails), plus undo restoring the
    original after each fracture; with RUBBLE_SCREENSHOT=FILE it also saves a screenshot of the sidebar panel.
"""

import os
import subprocess
import sys
import tempfile
import traceback

import bmesh
import bpy

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "integrations", "blender"))

import rubble_fracture  # noqa: E402


def world_volume(obj):
    """Signed volume of obj's mesh in world coordinates (bmesh)."""
    bm = bmesh.new()
    bm.from_mesh(obj.data)
    bm.transform(obj.matrix_world)
    v = bm.calc_volume(signed=True)
    bm.free()
    return v


def reset_scene():
    for o in list(bpy.data.objects):
        bpy.data.objects.remove(o)
    bpy.context.scene.cursor.location = (0, 0, 0)


def fracture(obj, cells, seed, impulse=400.0, depth=1):
    for o in bpy.context.view_layer.objects:
        o.select_set(o == obj)
    bpy.context.view_layer.objects.active = obj
    s = bpy.context.scene.rubble
    s.pattern, s.cells, s.seed, s.impulse, s.depth = "SHATTER", cells, seed, impulse, depth
    if bpy.app.background:
        return bpy.ops.rubble.fracture_at_cursor()
    with bpy.context.temp_override(window=bpy.context.window_manager.windows[0]):
        return bpy.ops.rubble.fracture_at_cursor("EXEC_DEFAULT", True)  # True: push an undo step, as the UI does


def check_fracture(name, obj, cursor, cells):
    bpy.context.scene.cursor.location = cursor
    input_volume = world_volume(obj)
    input_vertices = len(obj.data.vertices)
    assert input_volume > 0, (name, input_volume)
    if not bpy.app.background:
        with bpy.context.temp_override(window=bpy.context.window_manager.windows[0]):
            bpy.ops.ed.undo_push(message="before fracture")
    result = fracture(obj, cells=cells, seed=3)
    assert result == {"FINISHED"}, (name, result)
    pieces = [o for o in bpy.context.scene.objects if o.get("rubble_source") == name]
    assert len(pieces) >= 2, (name, len(pieces))
    assert bpy.data.objects.get(name) is None, "%s: the original was not replaced" % name
    total = sum(world_volume(p) for p in pieces)
    assert abs(total - input_volume) <= 1e-6 * input_volume, (name, total, input_volume)
    cut_faces = 0
    for p in pieces:
        slots = [m.name for m in p.data.materials]
        assert slots[-1] == rubble_fracture.INTERIOR_NAME, slots
        interior = len(slots) - 1
        cut_faces += sum(1 for f in p.data.polygons if f.material_index == interior)
        # The origin is the centre of mass: the mesh's own centroid (bmesh) is at the local origin.
        bm = bmesh.new()
        bm.from_mesh(p.data)
        assert abs(bm.calc_volume(signed=True)) > 0
        bm.free()
    assert cut_faces > 0, "%s: no face carries the interior material" % name
    print("%s: %d pieces, volume %.9g = input %.9g, %d cut faces" % (name, len(pieces), total, input_volume,
                                                                         cut_faces))
    if bpy.app.background:
        return None  # undo needs a window: checked by the Xvfb run
    # Undo brings the original back and removes the pieces.
    with bpy.context.temp_override(window=bpy.context.window_manager.windows[0]):
        bpy.ops.ed.undo()
    restored = bpy.data.objects.get(name)
    assert restored is not None, "%s: undo did not restore the original (objects: %s)" % (
        name, [o.name for o in bpy.data.objects])
    assert abs(world_volume(restored) - input_volume) <= 1e-9 * input_volume
    assert len(restored.data.vertices) == input_vertices, (len(restored.data.vertices), input_vertices)
    assert not [o for o in bpy.context.scene.objects if o.get("rubble_source") == name], "undo left pieces"
    print("%s: undo restores the original" % name)
    return restored


def test_cube_and_suzanne():
    reset_scene()
    bpy.ops.mesh.primitive_cube_add(size=2.0, location=(1.0, 0.5, 0.0))
    cube = bpy.context.active_object
    cube.name = "Cube"
    bm = bmesh.new()
    bm.from_mesh(cube.data)
    bmesh.ops.subdivide_edges(bm, edges=bm.edges[:], cuts=3, use_grid_fill=True)
    bm.to_mesh(cube.data)
    bm.free()
    check_fracture("Cube", cube, (1.6, 0.9, 0.3), cells=6)

    # Suzanne is open (eye holes): refused with a report, the original untouched.
    bpy.ops.mesh.primitive_monkey_add(location=(-3.0, 0.0, 0.0))
    open_monkey = bpy.context.active_object
    open_monkey.name = "OpenSuzanne"
    before = len(open_monkey.data.polygons)
    try:
        result = fracture(open_monkey, cells=4, seed=1)
    except RuntimeError as e:  # operators that report ERROR raise in background mode
        result = {"CANCELLED"}
        assert "not a closed solid" in str(e), str(e)
    assert result == {"CANCELLED"}, result
    assert bpy.data.objects.get("OpenSuzanne") is not None and len(open_monkey.data.polygons) == before

    # Closed by a voxel Remesh modifier (the add-on fractures the evaluated mesh).
    bpy.ops.mesh.primitive_monkey_add(location=(4.0, 0.0, 0.0))
    monkey = bpy.context.active_object
    monkey.name = "Suzanne"
    remesh = monkey.modifiers.new("Remesh", "REMESH")
    remesh.mode = "VOXEL"
    remesh.voxel_size = 0.06
    bpy.context.view_layer.update()
    depsgraph = bpy.context.evaluated_depsgraph_get()
    evaluated = monkey.evaluated_get(depsgraph)
    solid = bpy.data.meshes.new_from_object(evaluated)
    monkey.modifiers.clear()
    monkey.data = solid
    # Triangles, so that the input's volume does not depend on how non-planar quads are split.
    bm = bmesh.new()
    bm.from_mesh(solid)
    bmesh.ops.triangulate(bm, faces=bm.faces[:])
    bm.to_mesh(solid)
    bm.free()
    check_fracture("Suzanne", monkey, (4.2, -0.5, 0.2), cells=5)


def rough_cut_vertices(surface, set_roughness=False):
    """Vertices of the pieces of a 2 m cube fractured with the panel's surface settings (volume checked)."""
    reset_scene()
    bpy.ops.mesh.primitive_cube_add(size=2.0)
    cube = bpy.context.active_object
    cube.name = "RoughBox"
    bpy.context.scene.cursor.location = (0.7, 0.2, 0.1)
    s = bpy.context.scene.rubble
    s.material, s.set_roughness, s.roughness, s.hurst = surface, set_roughness, 0.15, 0.6
    try:
        assert fracture(cube, cells=4, seed=5) == {"FINISHED"}
    finally:
        s.material, s.set_roughness = "FLAT", False
    pieces = [o for o in bpy.context.scene.objects if o.get("rubble_source") == "RoughBox"]
    total = sum(world_volume(p) for p in pieces)
    assert abs(total - 8.0) <= 1e-6 * 8.0, (surface, total)
    return sum(len(p.data.vertices) for p in pieces)


def test_surface_presets():
    flat = rough_cut_vertices("FLAT")
    concrete = rough_cut_vertices("concrete")
    by_hand = rough_cut_vertices("FLAT", set_roughness=True)
    steel = rough_cut_vertices("steel")
    # Rough cut faces are tessellated and displaced: many more vertices than the flat cut's.
    assert concrete > 3 * flat and by_hand > 3 * flat, (flat, concrete, by_hand)
    assert steel == flat, (steel, flat)
    print("surface: flat %d vertices, concrete %d, roughness 0.15 by hand %d, steel %d" % (flat, concrete,
                                                                                         by_hand, steel))


def test_rigid_bodies_and_export(tmp):
    reset_scene()
    bpy.ops.mesh.primitive_cube_add(size=2.0)
    cube = bpy.context.active_object
    cube.name = "Box"
    bpy.context.scene.cursor.location = (0.7, 0.2, 0.1)
    bpy.context.scene.rubble.rigid_body = True
    assert fracture(cube, cells=4, seed=5) == {"FINISHED"}
    pieces = [o for o in bpy.context.scene.objects if o.get("rubble_source") == "Box"]
    assert all(p.rigid_body is not None and p.rigid_body.collision_shape == "CONVEX_HULL" for p in pieces)
    for p in pieces:
        p.select_set(True)
    path = os.path.join(tmp, "export", "pieces.gltf")
    assert bpy.ops.rubble.export_gltf(filepath=path) == {"FINISHED"}
    import json

    doc = json.load(open(path))
    roots = [doc["nodes"][r] for r in doc["scenes"][0]["nodes"]]
    assert len(roots) == len(pieces), (len(roots), len(pieces))
    for r in roots:
        assert r["extras"]["rubble"]["volume"] > 0
        kids = [doc["nodes"][c]["name"] for c in r["children"]]
        assert kids and all(k.endswith("-convcolonly") for k in kids), kids
    print("export: %d pieces with collision children" % len(roots))


def test_import_depth2(tmp):
    reset_scene()
    out = os.path.join(tmp, "depth2")
    cli = os.environ["RUBBLE_CLI"]
    subprocess.run([cli, "fracture", os.path.join(ROOT, "assets", "models", "cube_588.obj"), "--impact",
                    "0.9,0.2,-0.1", "--impulse", "400", "--cells", "4", "--depth", "2", "--format", "gltf",
                    "-o", out], check=True, stdout=subprocess.DEVNULL)
    bpy.ops.import_scene.gltf(filepath=os.path.join(out, "pieces.gltf"))
    objects = bpy.context.scene.objects
    hulls = [o for o in objects if o.name.endswith("-convcolonly")]
    chunks = [o for o in objects if o.type == "MESH" and not o.name.endswith("-convcolonly")]
    assert hulls and chunks, (len(hulls), len(chunks))
    assert all(h.parent is not None and not h.parent.name.endswith("-convcolonly") for h in hulls)
    level2 = [c for c in chunks if c.parent is not None]
    assert level2, "no level-2 chunks under level-1 pieces"
    assert all(any(h.parent == c for h in hulls) for c in chunks), "a chunk without collision children"
    print("import: %d chunks (%d on level 2), %d collision children" % (len(chunks), len(level2), len(hulls)))


def screenshot(path):
    """Saves a screenshot of the window with the 3D view's sidebar open on the Rubble tab (for docs/authoring.md;
    Blender 3.4 has no API to choose a sidebar tab, so the tab is clicked with xdotool)."""
    reset_scene()
    bpy.ops.mesh.primitive_cube_add(size=2.0)
    bpy.context.scene.cursor.location = (0.6, -0.4, 0.5)
    window = bpy.context.window_manager.windows[0]
    tab = None
    for area in window.screen.areas:
        if area.type == "VIEW_3D":
            area.spaces[0].show_region_ui = True
            for region in area.regions:
                if region.type == "UI":
                    # The tabs run down the region's right edge: Item, Tool, View, then Rubble.
                    tab = (region.x + region.width - 9, window.height - (region.y + region.height) + 160)
            area.tag_redraw()

    def click():
        if tab is not None:
            # Escape closes the splash screen; then the tab is clicked.
            # In the background: Blender must handle the events while xdotool sends them.
            subprocess.Popen(["xdotool", "mousemove", "600", "400", "key", "Escape", "sleep", "0.5", "mousemove",
                              str(tab[0]), str(tab[1]), "sleep", "0.5", "click", "1", "sleep", "0.5",
                              "mousemove", "600", "400"])
            print("clicked the Rubble tab at", tab)
        return None

    def shoot():
        with bpy.context.temp_override(window=window):
            bpy.ops.screen.screenshot(filepath=path)
        print("screenshot:", path)
        sys.stdout.flush()
        os._exit(0)

    bpy.app.timers.register(click, first_interval=1.0)
    bpy.app.timers.register(shoot, first_interval=4.5)


def test_without_numpy():
    """numpy not importable (Debian's Blender started from a pyenv shell): the add-on registers, and the operator
    reports rubble's import error with the interpreter it needs and the fix, leaving the cube as it was."""
    rubble_fracture.unregister()
    names = [n for n in sys.modules if n.split(".")[0] in ("numpy", "rubble")]
    saved = {n: sys.modules.pop(n) for n in names}
    sys.modules["numpy"] = None  # import numpy raises ImportError
    try:
        rubble_fracture.register()
        reset_scene()
        bpy.ops.mesh.primitive_cube_add(size=2.0)
        cube = bpy.context.active_object
        message = ""
        try:
            result = fracture(cube, cells=4, seed=1)
        except RuntimeError as e:  # operators that report ERROR raise in background mode
            result, message = {"CANCELLED"}, str(e)
        assert result == {"CANCELLED"}, result
        if bpy.app.background:
            assert "numpy" in message and "/python3" in message and "pyenv shell system" in message, message
        assert len(bpy.context.scene.objects) == 1 and len(cube.data.polygons) == 6
    finally:
        del sys.modules["numpy"]
        for n in [n for n in sys.modules if n.split(".")[0] == "rubble"]:
            del sys.modules[n]
        sys.modules.update(saved)
        rubble_fracture.unregister()
        rubble_fracture.register()


def run_all():
    rubble_fracture.register()
    try:
        with tempfile.TemporaryDirectory() as tmp:
            test_without_numpy()
            test_cube_and_suzanne()
            test_surface_presets()
            test_rigid_bodies_and_export(tmp)
            test_import_depth2(tmp)
    except Exception:
        traceback.print_exc()
        sys.stdout.flush()
        os._exit(1)
    print("test_addon: ok")
    sys.stdout.flush()


def main():
    if bpy.app.background:
        run_all()
        sys.exit(0)

    def windowed():
        run_all()
        if os.environ.get("RUBBLE_SCREENSHOT"):
            screenshot(os.environ["RUBBLE_SCREENSHOT"])
            return None
        os._exit(0)

    bpy.app.timers.register(windowed, first_interval=1.0)


main()
