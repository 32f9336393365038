"""Meshes from Python against the native mesh: the golden checksums that
format/mesh_builder_test.cc and format/mesh_simplify_test.cc pin (the same
FNV-1a over the same arrays, format/testing/mesh_checksum.h), on the same
"blocks" panorama made here in numpy; and triangle counts against
`casual3d export`."""

import re
import threading
import time

import numpy as np

import casual3d
from conftest import VECTORS


def mesh_checksum(mesh):
    """format/testing/mesh_checksum.h MeshChecksum: 64-bit FNV-1a over the
    bytes of positions, normals, uvs, colours and indices, in that order."""
    h = 1469598103934665603
    for array in (mesh.positions, mesh.normals, mesh.uvs, mesh.colors, mesh.indices):
        for byte in np.ascontiguousarray(array).tobytes():
            h = ((h ^ byte) * 1099511628211) & 0xFFFFFFFFFFFFFFFF
    return h


def make_blocks_panorama():
    """format/testing/mesh_checksum.h MakeBlocksPanorama, in numpy."""
    w, h = 512, 256
    y, x = np.mgrid[0:h, 0:w]
    near = (x // 40 + y // 30) % 5 == 0
    f32 = np.float32
    background = f32(3.0) + f32(0.01) * ((x + 2 * y) % 100).astype(f32)
    near_depth = f32(1.0) + f32(0.001) * ((x * 7 + y * 3) % 50).astype(f32)
    pano = casual3d.Panorama.empty(w, h)
    for layer, depth, present in ((pano.front, np.where(near, near_depth, background), True),
                                  (pano.back, background, near)):
        layer.depth[:] = np.where(present, depth, np.nan)
        layer.normals[:] = np.where(np.asarray(present)[..., None], [0, 0, 1], np.nan)
        layer.color[..., 0] = x & 255
        layer.color[..., 1] = y & 255
    pano.back.color[..., 2] = 100
    pano.back.color[~near] = 0
    pano.back.labels[near] = casual3d.LABEL_B
    return casual3d.link_neighbours(pano, 0.75)


def test_full_mesh_matches_native_golden_checksum():
    mesh = casual3d.build_mesh(make_blocks_panorama())
    assert mesh.num_triangles == 309166
    assert mesh.num_vertices == 159715
    assert mesh.positions.dtype == np.float32 and mesh.indices.dtype == np.uint32
    assert mesh.atlas.shape == (512, 512, 3)
    assert mesh_checksum(mesh) == 0x826F4ABBEC0B7206


def test_simplified_mesh_matches_native_golden_checksum():
    mesh = casual3d.build_mesh(make_blocks_panorama(), simplify=True, max_triangles=60000)
    assert not mesh.budget_met
    assert mesh.num_triangles == 84680
    assert abs(mesh.error_bound - 0.0099458673551007237) < 1e-15
    assert mesh_checksum(mesh) == 0xAD6F8A6948137764


def test_mesh_arrays_are_consistent(room):
    mesh = casual3d.build_mesh(room, threads=1)
    assert mesh.indices.max() < mesh.num_vertices
    assert np.all(np.isfinite(mesh.positions))
    # Every vertex lies at its node's depth along its ray; front nodes of the
    # room are 1.0-3.0 m away.
    distance = np.linalg.norm(mesh.positions, axis=1)
    assert distance.min() > 0.99 and distance.max() < 3.01
    again = casual3d.build_mesh(room, threads=3)
    assert np.array_equal(again.indices, mesh.indices)
    assert np.array_equal(again.positions, mesh.positions)
    front_only = casual3d.build_mesh(room, include_back_layer=False)
    assert front_only.num_triangles < mesh.num_triangles


def test_triangle_counts_match_casual3d_export(cli, tmp_path):
    for vector in ("two-layer-64x32", "front-only-48x24.c3d"):
        pano = casual3d.read(VECTORS / vector)
        for flags, mesh in (([], casual3d.build_mesh(pano, simplify=True)),
                            (["--no-simplify"], casual3d.build_mesh(pano))):
            out = cli("export", VECTORS / vector, "--glb", tmp_path / "native.glb", *flags)
            assert out.returncode == 0, out.stderr
            counts = re.search(r"(\d+) vertices, (\d+) triangles", out.stdout)
            assert int(counts.group(2)) == mesh.num_triangles, (vector, flags)


def test_long_calls_release_the_gil():
    """While a mesh is built on another thread, this thread keeps running:
    its longest pause is far shorter than the call (the GIL is released)."""
    blocks = make_blocks_panorama()
    tile = lambda a: np.tile(a, (2, 2) + (1,) * (a.ndim - 2))  # 1024 x 512 pixels.
    big = casual3d.Panorama(*(casual3d.Layer(**{k: tile(a) for k, a in vars(layer).items()})
                              for layer in blocks.layers))
    casual3d.link_neighbours(big)
    done = threading.Event()

    def work():
        casual3d.build_mesh(big, simplify=True, threads=1)
        done.set()

    start = time.perf_counter()
    worker = threading.Thread(target=work)
    worker.start()
    last, longest_pause = start, 0.0
    while not done.is_set():
        now = time.perf_counter()
        longest_pause = max(longest_pause, now - last)
        last = now
    worker.join()
    duration = time.perf_counter() - start
    assert duration > 0.2
    # Held through the call, the GIL would stop this loop for nearly all of
    # it; the margin is for a busy machine's scheduling.
    assert longest_pause < 0.5 * duration, (longest_pause, duration)
