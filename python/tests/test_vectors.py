"""The spec's test vectors (spec/vectors/, spec/package.md Sec. 9) read from
Python give the figures of expected.json; the invalid ones are refused with
the messages of `casual3d validate`."""

import hashlib
import json

import numpy as np
import pytest

import casual3d
from conftest import VECTORS

EXPECTED = json.loads((VECTORS / "expected.json").read_text())
VALID = [(name, form) for name in EXPECTED for form in ("", ".c3d")]
INVALID = sorted(p.name for p in (VECTORS / "invalid").iterdir())


def summary(pano):
    """The figures expected.json lists for one level (spec/package.md Sec. 9)."""
    out = {"width": pano.width, "height": pano.height, "present": [], "rgb_sum": [],
           "depth_sum_m": [], "normal_sum": []}
    graph = b""
    for layer in pano.layers:
        present = layer.present
        out["present"].append(int(present.sum()))
        out["rgb_sum"].append(int(layer.color[present].astype(np.int64).sum()))
        out["depth_sum_m"].append(float(layer.depth[present].astype(np.float64).sum()))
        out["normal_sum"].append(layer.normals[present].astype(np.float64).sum(axis=0).tolist())
        graph += (present.astype(np.uint8).tobytes() + layer.labels.tobytes() +
                  layer.packed_links().tobytes())
    out["graph_sha256"] = hashlib.sha256(graph).hexdigest()
    return out


@pytest.mark.parametrize("name,form", VALID)
def test_valid_vector_matches_expected(name, form):
    package = casual3d.Package(VECTORS / (name + form))
    assert package.num_levels == len(EXPECTED[name])
    assert package.manifest["format"] == "casual3d"
    assert (package.manifest["width"], package.manifest["height"]) == (
        EXPECTED[name][0]["width"], EXPECTED[name][0]["height"])
    for level, want in enumerate(EXPECTED[name]):
        got = summary(package.read(level))
        for key in ("width", "height", "present", "rgb_sum", "graph_sha256"):
            assert got[key] == want[key], (level, key)
        for l in range(2):
            assert got["depth_sum_m"][l] == pytest.approx(want["depth_sum_m"][l], rel=1e-6,
                                                           abs=1e-9)
            assert got["normal_sum"][l] == pytest.approx(want["normal_sum"][l], abs=1e-3)


@pytest.mark.parametrize("name", list(EXPECTED))
def test_validate_reports_every_level(name, cli):
    levels = casual3d.validate(VECTORS / name)
    assert [lv["level"] for lv in levels] == list(range(len(EXPECTED[name])))
    for got, want in zip(levels, EXPECTED[name]):
        assert (got["width"], got["height"]) == (want["width"], want["height"])
        assert [got["front_nodes"], got["back_nodes"]] == want["present"]
    out = cli("validate", VECTORS / name)
    assert out.returncode == 0
    for got in levels:
        assert (f"level {got['level']}: {got['width']}x{got['height']} ok, "
                f"{got['front_nodes']} front and {got['back_nodes']} back nodes, "
                f"{got['files']} files verified") in out.stdout


@pytest.mark.parametrize("name", INVALID)
def test_invalid_vector_refused_as_cli_does(name, cli):
    path = VECTORS / "invalid" / name
    with pytest.raises(casual3d.FormatError) as error:
        casual3d.validate(path)
    assert str(path) in str(error.value)
    assert isinstance(error.value, ValueError)
    out = cli("validate", path)
    assert out.returncode == 1
    assert out.stderr.strip() == f"casual3d: error: {error.value}"
    with pytest.raises(casual3d.FormatError, match=str(path)) as read_error:
        casual3d.read(path)
    # Each place is named once (it once read "manifest.json: manifest.json: ...").
    assert str(read_error.value).count("manifest.json:") <= 1


def mesh_sha256(mesh):
    """spec/package.md Sec. 9: SHA-256 of positions, normals, uvs (float32)
    and indices (uint32), each little-endian, in that order."""
    digest = hashlib.sha256()
    for array, dtype in ((mesh.positions, "<f4"), (mesh.normals, "<f4"), (mesh.uvs, "<f4"),
                         (mesh.indices, "<u4")):
        digest.update(np.ascontiguousarray(array, dtype).tobytes())
    return digest.hexdigest()


@pytest.mark.parametrize("name", list(EXPECTED))
def test_vector_meshes_match_expected(name):
    package = casual3d.Package(VECTORS / name)
    for level, want in enumerate(EXPECTED[name]):
        if "mesh" not in want:
            pytest.skip(f"expected.json lists no meshes for {name} level {level}")
        pano = package.read(level)
        full = casual3d.build_mesh(pano, threads=1)
        expected = want["mesh"]["full"]
        assert (full.num_vertices, full.num_triangles) == (expected["vertices"],
                                                           expected["triangles"])
        assert mesh_sha256(full) == expected["sha256"]
        for expected in want["mesh"]["simplified"]:
            mesh = casual3d.build_mesh(pano, simplify=True, max_triangles=0, threads=1,
                                       max_relative_error=expected["max_relative_error"])
            assert (mesh.num_vertices, mesh.num_triangles) == (expected["vertices"],
                                                               expected["triangles"])
            assert mesh_sha256(mesh) == expected["sha256"]
