"""write_obj from several threads to one path: every call succeeds, and a reader never sees a partial file
(each call stages its own temporary file, renamed over the target)."""

import threading

import rubble


def test_threads_writing_one_path_never_fail_and_readers_see_whole_files(tmp_path):
    path = tmp_path / "shared.obj"
    meshes = [rubble.box((0, 0, 0), (1, 1, 1), 12), rubble.box((0, 0, 0), (2, 2, 2), 12)]
    rubble.write_obj(path, meshes[0])
    errors, reads = [], []
    done = threading.Event()

    def writer(mesh):
        try:
            for _ in range(60):
                rubble.write_obj(path, mesh)
        except Exception as e:  # noqa: BLE001 (every failure is the finding)
            errors.append(e)

    def reader():
        while not done.is_set():
            try:
                reads.append(rubble.read_mesh(path).triangle_count)
            except Exception as e:  # noqa: BLE001
                errors.append(e)

    writers = [threading.Thread(target=writer, args=(m,)) for m in meshes]
    watcher = threading.Thread(target=reader)
    watcher.start()
    for w in writers:
        w.start()
    for w in writers:
        w.join()
    done.set()
    watcher.join()
    assert errors == []
    assert reads and set(reads) == {meshes[0].triangle_count}
    assert round(rubble.read_mesh(path).volume, 9) in (1.0, 8.0)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["shared.obj"]
