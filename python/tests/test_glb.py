"""export_glb writes binary glTF with the counts of the mesh it exports."""

import json
import struct

import casual3d
from conftest import VECTORS


def read_glb(path):
    data = path.read_bytes()
    magic, version, length = struct.unpack_from("<4sII", data)
    assert (magic, version, length) == (b"glTF", 2, len(data))
    chunk_length, chunk_type = struct.unpack_from("<II", data, 12)
    assert chunk_type == 0x4E4F534A  # "JSON"
    return json.loads(data[20:20 + chunk_length])


def test_export_glb_counts(room, tmp_path):
    mesh = casual3d.build_mesh(room, simplify=True)
    stats = casual3d.export_glb(room, tmp_path / "room.glb", texture="png")
    gltf = read_glb(tmp_path / "room.glb")
    primitive = gltf["meshes"][0]["primitives"][0]
    accessors = gltf["accessors"]
    assert accessors[primitive["indices"]]["count"] == 3 * mesh.num_triangles
    assert accessors[primitive["attributes"]["POSITION"]]["count"] == mesh.num_vertices
    assert stats["num_triangles"] == mesh.num_triangles
    assert (stats["texture_width"], stats["texture_height"]) == (room.width, 2 * room.height)
    assert gltf["images"][0]["mimeType"] == "image/png"


def test_export_glb_draco_from_a_package_path(tmp_path):
    pano = casual3d.read(VECTORS / "two-layer-64x32.c3d")
    full = casual3d.build_mesh(pano)
    stats = casual3d.export_glb(VECTORS / "two-layer-64x32.c3d", tmp_path / "d.glb",
                                draco=True, simplify=False)
    gltf = read_glb(tmp_path / "d.glb")
    assert "KHR_draco_mesh_compression" in gltf["extensionsRequired"]
    primitive = gltf["meshes"][0]["primitives"][0]
    assert "KHR_draco_mesh_compression" in primitive["extensions"]
    assert gltf["accessors"][primitive["indices"]]["count"] == 3 * full.num_triangles
    assert stats["num_triangles"] == full.num_triangles
    assert stats["draco_position_bits"] >= 14
    coarse = casual3d.export_glb(casual3d.Package(VECTORS / "two-layer-64x32"),
                                 tmp_path / "c.glb", level=1, simplify=False)
    assert coarse["texture_width"] == 32
