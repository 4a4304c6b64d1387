"""Rubble Fracture: break the selected mesh at the 3D cursor into pieces with Rubble, and export pieces as
engine-ready glTF (convex collision parts as "-convcolonly" children, mass properties in extras).

Needs the `rubble` Python module (built for the system python3 that Debian's Blender uses): `make blender-addon`
installs this add-on and records where the module is; RUBBLE_PYTHON_DIR overrides it. See docs/authoring.md.
"""

import os
import sys

import bpy
import bmesh
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty, StringProperty
from mathutils import Vector

bl_info = {
    "name": "Rubble Fracture",
    "author": "Rubble",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "View3D > Sidebar > Rubble",
    "description": "Fracture meshes at the 3D cursor with Rubble; export engine-ready glTF",
    "category": "Object",
}

INTERIOR_NAME = "Rubble Interior"


def _module_dirs():
    """Where the rubble module may be: RUBBLE_PYTHON_DIR, then the path recorded by `make blender-addon`."""
    dirs = []
    if os.environ.get("RUBBLE_PYTHON_DIR"):
        dirs.append(os.environ["RUBBLE_PYTHON_DIR"])
    recorded = os.path.join(os.path.dirname(__file__), "rubble_path.txt")
    if os.path.exists(recorded):
        with open(recorded, encoding="utf-8") as f:
            dirs.append(f.read().strip())
    return dirs


def load_rubble():
    """The rubble module, or raises ImportError with a message saying how to get it."""
    for d in _module_dirs():
        if d and d not in sys.path:
            sys.path.insert(0, d)
    try:
        import rubble  # noqa: PLC0415 (imported on first use: the add-on registers without it)
    except ImportError as e:
        if "rubble needs" in str(e):  # found, but numpy or its extension cannot load in this Python
            raise ImportError(
                "Rubble cannot load in Blender's Python: %s Fix: install python3-numpy and start Blender from a "
                "shell where Debian's /usr/bin/python3 comes first on PATH (e.g. after `pyenv shell system`), "
                "with PYTHONPATH and PYTHONHOME unset" % e
            ) from e
        raise ImportError(
            "the rubble Python module is not found (%s); build Rubble and run `make blender-addon`, or set "
            "RUBBLE_PYTHON_DIR to the folder holding the rubble package" % e
        ) from e
    return rubble


class RubbleSettings(bpy.types.PropertyGroup):
    pattern: EnumProperty(
        name="Pattern",
        items=[
            ("SINGLE", "Single cell", "The thesis's single Voronoi cell at the impact"),
            ("SHATTER", "Shatter", "Shatter into Cells Voronoi cells around the impact"),
        ],
        default="SHATTER",
    )
    cells: IntProperty(name="Cells", default=8, min=2, max=200, description="Cells of the shatter pattern")
    seed: IntProperty(name="Seed", default=1, min=0, description="Same seed, same pieces")
    impulse: FloatProperty(name="Impulse", default=400.0, min=0.0, description="Impact impulse (N s): the "
                           "size of the cut region grows with it")
    material: EnumProperty(
        name="Surface",
        items=[
            ("FLAT", "Flat", "The thesis's flat Voronoi planes"),
            ("concrete", "Concrete", "Rough, self-affine cut faces (Hurst 0.75)"),
            ("stone", "Stone", "Rough, a little smoother than concrete (Hurst 0.8)"),
            ("brick", "Brick", "Rough at the mortar scale (12 mm amplitude)"),
            ("wood", "Wood", "Fibrous: wavelengths 6 times longer along the grain"),
            ("glass", "Glass", "Nearly flat, shallow conchoidal undulation"),
            ("steel", "Steel", "Flat"),
        ],
        default="FLAT",
        description="Cut-surface preset of a material (docs/roughness.md)",
    )
    set_roughness: BoolProperty(name="Set roughness", default=False, description="Set the amplitude and "
                                "Hurst exponent by hand, over the surface preset")
    roughness: FloatProperty(name="Roughness", default=0.1, min=0.0, max=1.0, description="Amplitude of the "
                             "cut faces relative to the cell size (0 = flat)")
    hurst: FloatProperty(name="Hurst", default=0.75, min=0.05, max=1.0, description="Roughness exponent: "
                         "higher is smoother at small scales")
    depth: IntProperty(name="Depth", default=1, min=1, max=3, description="Levels: each piece is shattered "
                       "again Depth-1 times (the leaves become objects)")
    rigid_body: BoolProperty(name="Rigid bodies", default=False, description="Give every piece a rigid body "
                             "with a convex hull shape and its mass (density 1)")
    export_path: StringProperty(name="glTF file", default="//pieces.gltf", subtype="FILE_PATH")


def _triangulated_world_mesh(obj, depsgraph):
    """Triangles of obj's evaluated mesh in world coordinates: (vertices, triangles, material ids, corner uvs)."""
    import numpy as np  # noqa: PLC0415

    evaluated = obj.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    try:
        bm = bmesh.new()
        bm.from_mesh(mesh)
        bmesh.ops.triangulate(bm, faces=bm.faces[:])
        bm.transform(obj.matrix_world)
        bm.verts.index_update()
        uv = bm.loops.layers.uv.active
        verts = np.array([v.co[:] for v in bm.verts], dtype=np.float64).reshape(-1, 3)
        tris = np.array([[v.index for v in f.verts] for f in bm.faces], dtype=np.int64).reshape(-1, 3)
        mats = np.array([f.material_index for f in bm.faces], dtype=np.uint32)
        uvs = None
        if uv is not None:
            uvs = np.array([l[uv].uv[:] for f in bm.faces for l in f.loops], dtype=np.float64).reshape(-1, 2)
        bm.free()
    finally:
        evaluated.to_mesh_clear()
    return verts, tris, mats, uvs


def _surface(settings):
    """The cut-surface keywords of rubble.fracture for the panel's settings."""
    surface = {}
    if settings.material != "FLAT":
        surface["material"] = settings.material
    if settings.set_roughness:
        surface["roughness"] = settings.roughness
        surface["hurst"] = settings.hurst
    return surface


def _fracture_levels(rubble, mesh, settings, point):
    """Pieces of mesh at point, and with depth > 1 every piece shattered again around its centre of mass."""
    cells = settings.cells if settings.pattern == "SHATTER" else 1
    surface = _surface(settings)
    pieces = rubble.fracture(mesh, point=point, impulse=settings.impulse, cells=cells, seed=settings.seed,
                             **surface)
    for level in range(2, settings.depth + 1):
        deeper = []
        for i, piece in enumerate(pieces):
            lo, hi = piece.vertices.min(axis=0), piece.vertices.max(axis=0)
            size = float(((hi - lo) ** 2).sum() ** 0.5)
            # The cell size law: 0.5 + 0.05 sqrt(impulse); an impulse whose region covers the piece.
            impulse = max(0.0, (size - 0.5) / 0.05) ** 2 + 1.0
            try:
                sub = rubble.fracture(piece, point=piece.center_of_mass, impulse=impulse,
                                      cells=max(2, settings.cells), seed=settings.seed * 7919 + i + level,
                                      **surface)
            except rubble.Error:
                sub = [piece]  # kept whole on this level
            deeper.extend(sub)
        pieces = deeper
    return pieces


def _interior_material():
    mat = bpy.data.materials.get(INTERIOR_NAME)
    if mat is None:
        mat = bpy.data.materials.new(INTERIOR_NAME)
        mat.diffuse_color = (0.85, 0.45, 0.2, 1.0)
    return mat


def _piece_object(rubble, piece, source, name, collection):
    """A new object for piece: origin at its centre of mass, the source's materials plus the interior one."""
    com = Vector(piece.center_of_mass)
    me = bpy.data.meshes.new(name)
    verts = [Vector(v) - com for v in piece.vertices]
    me.from_pydata(verts, [], [tuple(int(i) for i in t) for t in piece.triangles])
    for m in source.data.materials:
        me.materials.append(m)
    interior_slot = len(me.materials)
    me.materials.append(_interior_material())
    mats = piece.materials
    if mats is not None:
        me.polygons.foreach_set(
            "material_index",
            [interior_slot if int(m) == rubble.INTERIOR_MATERIAL else int(m) for m in mats],
        )
    uvs = piece.uvs
    if uvs is not None:
        layer = me.uv_layers.new(name="UVMap")
        layer.data.foreach_set("uv", [c for uv in uvs for c in uv])
    me.validate()
    me.update()
    obj = bpy.data.objects.new(name, me)
    obj.location = com
    obj["rubble_volume"] = float(piece.volume)
    collection.objects.link(obj)
    return obj


def _add_rigid_body(context, obj, mass):
    if context.scene.rigidbody_world is None:
        with context.temp_override(scene=context.scene):
            bpy.ops.rigidbody.world_add()
    with context.temp_override(object=obj, active_object=obj, selected_objects=[obj]):
        bpy.ops.rigidbody.object_add()
    obj.rigid_body.collision_shape = "CONVEX_HULL"
    obj.rigid_body.mass = max(mass, 1e-6)


class RUBBLE_OT_fracture_at_cursor(bpy.types.Operator):
    """Replace the active mesh object with Rubble's pieces of a fracture at the 3D cursor"""

    bl_idname = "rubble.fracture_at_cursor"
    bl_label = "Rubble: Fracture at 3D cursor"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        obj = context.active_object
        return obj is not None and obj.type == "MESH"

    def execute(self, context):
        settings = context.scene.rubble
        source = context.active_object
        # Everything is computed before the scene changes: any failure leaves the original as it was.
        try:
            rubble = load_rubble()
            verts, tris, mats, uvs = _triangulated_world_mesh(source, context.evaluated_depsgraph_get())
            mesh = rubble.Mesh(verts, tris, materials=mats, uvs=uvs)
            report = rubble.check(mesh)
            if not report.valid:
                problems = "; ".join(report.problems[:2]) or "invalid mesh"
                self.report({"ERROR"}, "%s is not a closed solid, Rubble cannot fracture it: %s (close it, e.g. "
                            "with a Remesh modifier)" % (source.name, problems))
                return {"CANCELLED"}
            pieces = _fracture_levels(rubble, mesh, settings, tuple(context.scene.cursor.location))
        except ImportError as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        except Exception as e:  # library errors (rubble.Error) and bad input alike become reports
            self.report({"ERROR"}, "Rubble could not fracture %s: %s" % (source.name, e))
            return {"CANCELLED"}
        if len(pieces) < 2:
            self.report({"WARNING"}, "Nothing was cut: the impact's cells contain all of %s or miss it" %
                        source.name)
            return {"CANCELLED"}

        collection = source.users_collection[0] if source.users_collection else context.scene.collection
        created = []
        for i, piece in enumerate(pieces):
            obj = _piece_object(rubble, piece, source, "%s_%03d" % (source.name, i), collection)
            obj["rubble_source"] = source.name
            obj["rubble_convex_parts"] = len(piece.convex_parts)
            if settings.rigid_body:
                _add_rigid_body(context, obj, float(piece.volume))
            created.append(obj)
        for obj in context.view_layer.objects:
            obj.select_set(obj in created)
        context.view_layer.objects.active = created[0]
        bpy.data.objects.remove(source)
        self.report({"INFO"}, "%d pieces" % len(created))
        return {"FINISHED"}


class RUBBLE_OT_export_gltf(bpy.types.Operator):
    """Export the selected mesh objects as Rubble's engine-ready glTF (convex collision parts, mass in extras)"""

    bl_idname = "rubble.export_gltf"
    bl_label = "Rubble: Export pieces as glTF"

    filepath: StringProperty(subtype="FILE_PATH")

    @classmethod
    def poll(cls, context):
        return any(o.type == "MESH" for o in context.selected_objects)

    def execute(self, context):
        path = bpy.path.abspath(self.filepath or context.scene.rubble.export_path)
        wm = context.window_manager
        objects = sorted((o for o in context.selected_objects if o.type == "MESH"), key=lambda o: o.name)
        # Progress over all objects, 0..100: each object's decomposition fills its share.
        wm.progress_begin(0, 100)
        try:
            rubble = load_rubble()
            nodes = []
            depsgraph = context.evaluated_depsgraph_get()
            for k, obj in enumerate(objects):
                verts, tris, mats, uvs = _triangulated_world_mesh(obj, depsgraph)
                slots = [m.name if m else "" for m in obj.data.materials]
                mats = [rubble.INTERIOR_MATERIAL if i < len(slots) and slots[i] == INTERIOR_NAME else int(i)
                        for i in mats]
                mesh = rubble.Mesh(verts, tris, materials=mats, uvs=uvs)

                def progress(fraction, k=k):
                    wm.progress_update(100 * (k + fraction) / len(objects))

                parts = rubble.decompose(mesh, progress=progress, threads=os.cpu_count() or 1)
                nodes.append((obj.name, mesh, parts))
            os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
            rubble.write_gltf(path, nodes)
        except KeyboardInterrupt:
            self.report({"WARNING"}, "Rubble export cancelled, nothing written")
            return {"CANCELLED"}
        except Exception as e:
            self.report({"ERROR"}, "Rubble could not export: %s" % e)
            return {"CANCELLED"}
        finally:
            wm.progress_end()
        self.report({"INFO"}, "%d pieces written to %s" % (len(nodes), path))
        return {"FINISHED"}


class RUBBLE_PT_panel(bpy.types.Panel):
    bl_label = "Rubble Fracture"
    bl_idname = "RUBBLE_PT_panel"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "Rubble"

    def draw(self, context):
        layout = self.layout
        settings = context.scene.rubble
        col = layout.column()
        col.prop(settings, "pattern")
        row = col.row()
        row.enabled = settings.pattern == "SHATTER"
        row.prop(settings, "cells")
        col.prop(settings, "seed")
        col.prop(settings, "impulse")
        col.prop(settings, "material")
        col.prop(settings, "set_roughness")
        row = col.row()
        row.enabled = settings.set_roughness
        row.prop(settings, "roughness")
        row.prop(settings, "hurst")
        col.prop(settings, "depth")
        col.prop(settings, "rigid_body")
        col.operator(RUBBLE_OT_fracture_at_cursor.bl_idname, icon="MOD_EXPLODE")
        layout.separator()
        layout.prop(settings, "export_path")
        layout.operator(RUBBLE_OT_export_gltf.bl_idname, icon="EXPORT").filepath = settings.export_path


classes = (RubbleSettings, RUBBLE_OT_fracture_at_cursor, RUBBLE_OT_export_gltf, RUBBLE_PT_panel)


def _numpy_bool_alias():
    """Debian's Blender 3.4 glTF importer uses np.bool, which Debian's numpy 1.24 removed: importing any glTF
    fails with AttributeError. The alias is the builtin bool, as it was until numpy 1.24. Without numpy the
    add-on still registers; its operators then report why Rubble cannot load (load_rubble)."""
    try:
        import numpy as np  # noqa: PLC0415
    except ImportError:
        return

    if "bool" not in np.__dict__:
        np.bool = bool


def register():
    _numpy_bool_alias()
    for c in classes:
        bpy.utils.register_class(c)
    bpy.types.Scene.rubble = PointerProperty(type=RubbleSettings)


def unregister():
    del bpy.types.Scene.rubble
    for c in reversed(classes):
        bpy.utils.unregister_class(c)
