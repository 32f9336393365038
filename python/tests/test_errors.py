"""Broken input raises Python exceptions that name the file; the interpreter
survives every one of them."""

import shutil

import numpy as np
import pytest

import casual3d
from conftest import VECTORS


def test_corrupt_package_names_the_file(tmp_path, cli):
    package = tmp_path / "corrupt"
    shutil.copytree(VECTORS / "two-layer-64x32", package)
    tile = sorted((package / "l0").iterdir())[0]
    data = bytearray(tile.read_bytes())
    data[len(data) // 2] ^= 0xFF
    tile.write_bytes(bytes(data))
    with pytest.raises(casual3d.FormatError) as error:
        casual3d.read(package)
    assert str(package) in str(error.value) and tile.name in str(error.value)
    with pytest.raises(casual3d.FormatError) as error:
        casual3d.validate(package)
    assert cli("validate", package).stderr.strip() == f"casual3d: error: {error.value}"
    # Without checksums the flipped byte reaches the WebP decoder, which must
    # refuse it or decode it into a panorama that still validates.
    try:
        casual3d.read(package, verify_checksums=False)
    except casual3d.FormatError as e:
        assert str(package) in str(e)


def test_truncated_single_file_names_the_file(tmp_path):
    path = tmp_path / "cut.c3d"
    path.write_bytes((VECTORS / "two-layer-64x32.c3d").read_bytes()[:300])
    with pytest.raises(casual3d.FormatError, match=str(path)):
        casual3d.read(path)
    with pytest.raises(casual3d.FormatError, match=str(path)):
        casual3d.Package(path)


def test_missing_and_foreign_files(tmp_path):
    with pytest.raises(casual3d.FormatError, match=str(tmp_path / "nothing")):
        casual3d.read(tmp_path / "nothing")
    text = tmp_path / "notes.txt"
    text.write_text("not a 3D photo")
    with pytest.raises(casual3d.FormatError, match=str(text)):
        casual3d.read(text)
    exr = tmp_path / "broken.exr"
    exr.write_bytes(b"\x76\x2f\x31\x01" + bytes(100))
    with pytest.raises(casual3d.FormatError, match=str(exr)):
        casual3d.read(exr)


def test_bad_arrays_and_options(room, tmp_path):
    bad = casual3d.Panorama(room.front, casual3d.Layer.empty(room.width + 1, room.height))
    with pytest.raises(ValueError, match=r"back.depth: shape \(64, 129\), expected \(64, 128\)"):
        casual3d.write_package(bad, tmp_path / "bad")
    room.front.links[3, 5, casual3d.UP] = 7
    with pytest.raises(ValueError, match=r"front.links: value 7 at pixel \(5, 3\)"):
        casual3d.build_mesh(room)
    room.front.links[3, 5, casual3d.UP] = casual3d.LINK_BACK  # No back node there: not mutual.
    with pytest.raises(ValueError, match=r"the panorama is invalid: .*\(5, 3\)"):
        casual3d.write_master(room, tmp_path / "m.exr")
    assert not (tmp_path / "m.exr").exists()
    casual3d.link_neighbours(room)
    with pytest.raises(ValueError, match="tile_size"):
        casual3d.write_package(room, tmp_path / "p", tile_size=5)
    with pytest.raises(TypeError, match="unknown option 'tile_sise'"):
        casual3d.write_package(room, tmp_path / "p", tile_sise=64)
    with pytest.raises(ValueError, match="max_relative_error"):
        casual3d.build_mesh(room, simplify=True, max_relative_error=2.0)
    with pytest.raises(casual3d.FormatError, match="view_hints"):
        room.view_hints = {"fov_deg": 500}
        casual3d.write_package(room, tmp_path / "p")


def test_unwritable_destination_is_an_os_error(room, tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    with pytest.raises(OSError, match=str(blocker)):
        casual3d.write_master(room, blocker / "master.exr")
    with pytest.raises(OSError, match=str(blocker)):
        casual3d.export_glb(room, blocker / "photo.glb")
