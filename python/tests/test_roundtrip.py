"""A panorama made in numpy, written from Python, checked by `casual3d
validate` and read back: master files exactly, packages exactly for the
lossless layers (presence, labels, links), within the spec's quantization for
depth and normals, and above 38 dB PSNR for the lossy colour."""

import numpy as np
import pytest

import casual3d


def psnr(a, b):
    mse = np.mean((a.astype(np.float64) - b.astype(np.float64)) ** 2)
    return 10 * np.log10(255.0 ** 2 / mse)


def assert_package_reads_back(written, read):
    assert (read.width, read.height) == (written.width, written.height)
    assert read.view_hints == written.view_hints
    for w, r in zip(written.layers, read.layers):
        present = w.present
        assert np.array_equal(r.present, present)
        assert np.array_equal(r.labels, w.labels)
        assert np.array_equal(r.links, w.links)
        assert np.all(np.isnan(r.depth[~present]))
        assert np.all(np.isnan(r.normals[~present]))
        if not present.any():
            continue
        # depth_bits 12: relative error below 0.09% (encoder/package_writer.h).
        relative = np.abs(r.depth[present] - w.depth[present]) / w.depth[present]
        assert relative.max() < 9e-4
        lit = present & np.any(w.normals != 0, axis=-1)
        cosine = np.sum(r.normals[lit] * w.normals[lit], axis=-1)
        assert np.all(np.degrees(np.arccos(np.clip(cosine, -1, 1))) < 1.0)
        assert np.all(r.normals[present & ~lit] == 0)
        assert psnr(r.color[present], w.color[present]) > 38.0


@pytest.mark.parametrize("name", ["web", "photo.c3d"])
def test_package_validates_with_cli_and_reads_back(room, tmp_path, cli, name):
    path = tmp_path / name
    sizes = casual3d.write_package(room, path)
    assert sizes["total_bytes"] > sizes["manifest_bytes"] > 0
    out = cli("validate", path)
    assert out.returncode == 0, out.stderr
    assert "valid casual3d 1.1 package" in out.stdout
    assert casual3d.validate(path)[0]["front_nodes"] == int(room.front.present.sum())
    assert_package_reads_back(room, casual3d.read(path))
    assert casual3d.read_manifest(path)["generator"] == f"casual3d {casual3d.__version__}"


def test_package_levels(room, tmp_path):
    casual3d.write_package(room, tmp_path / "web", tile_size=32, levels=2, threads=1)
    package = casual3d.Package(tmp_path / "web")
    assert package.num_levels == 2
    coarse = package.read(1)
    assert (coarse.width, coarse.height) == (room.width // 2, room.height // 2)
    assert [p.width for p in package.levels()] == [room.width, room.width // 2]
    with pytest.raises(IndexError, match="level 2 does not exist"):
        package.read(2)


def test_package_with_a_level_left_out(room, tmp_path, cli):
    path = tmp_path / "web"
    casual3d.write_package(room, path, tile_size=16, levels=3, omit_level_width=room.width // 2,
                           threads=1)
    out = cli("validate", path)
    assert out.returncode == 0, out.stderr
    assert "valid casual3d 2.0 package" in out.stdout
    package = casual3d.Package(path)
    assert [p.width for p in package.levels()] == [room.width, room.width // 4]
    coarse = package.read(1)
    assert (coarse.width, coarse.height) == (room.width // 4, room.height // 4)


def test_master_file_reads_back_exactly(room, tmp_path, cli):
    room.centre = np.array([0.5, -1.25, 3.0])
    room.rotation = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])
    path = tmp_path / "master.exr"
    casual3d.write_master(room, path)
    read = casual3d.read(path)
    np.testing.assert_array_equal(read.centre, room.centre)
    np.testing.assert_array_equal(read.rotation, room.rotation)
    assert read.view_hints == room.view_hints
    for w, r in zip(room.layers, read.layers):
        for field in ("color", "depth", "normals", "labels", "links"):
            np.testing.assert_array_equal(getattr(r, field), getattr(w, field), err_msg=field)
    # The CLI encodes it into a package that Python reads as it wrote it.
    # 12-bit depth and 8-bit normals: the encoder library's defaults, which the
    # checks below state (the CLI's own defaults are the smaller delivery codes).
    out = cli("encode", path, "-o", tmp_path / "encoded", "--depth-bits", "12", "--normal-bits", "8")
    assert out.returncode == 0, out.stderr
    assert_package_reads_back(room, casual3d.read(tmp_path / "encoded"))


def test_front_only_panorama_without_view_hints(tmp_path):
    pano = casual3d.Panorama.empty(64, 32)
    pano.front.depth[:] = np.linspace(2.0, 4.0, 32, dtype=np.float32)[:, None]
    pano.front.normals[:] = 0.0
    pano.front.color[:] = [90, 160, 70]
    casual3d.link_neighbours(pano)
    casual3d.write_package(pano, tmp_path / "p.c3d", color_quality=95)
    read = casual3d.read(tmp_path / "p.c3d")
    assert read.view_hints is None
    assert not read.back.present.any()
    assert_package_reads_back(pano, read)


def test_lossy_normals_keep_their_declared_bounds(room, tmp_path, cli):
    path = tmp_path / "lossy"
    casual3d.write_package(room, path, lossy_normals=True, normal_mean_error_deg=2.0,
                           normal_p99_error_deg=6.0)
    manifest = casual3d.read_manifest(path)
    assert manifest["version"] == "1.2"
    assert manifest["normal_encoding"] == {
        "type": "octahedral-lossy", "mean_error_deg": 2.0, "p99_error_deg": 6.0}
    out = cli("validate", path)
    assert out.returncode == 0, out.stderr
    read = casual3d.read(path)
    angles = []
    for w, r in zip(room.layers, read.layers):
        lit = w.present & np.any(w.normals != 0, axis=-1)
        assert np.all(r.normals[w.present & ~lit] == 0)
        cosine = np.sum(r.normals[lit] * w.normals[lit], axis=-1)
        angles.append(np.degrees(np.arccos(np.clip(cosine, -1, 1))))
    angles = np.concatenate(angles)
    # Each tile keeps both bounds over its lit nodes, so the whole level does.
    assert angles.size > 1000
    assert angles.mean() <= 2.0
    assert np.percentile(angles, 99, method="inverted_cdf") <= 6.0


def test_max_kb_fits_the_package_in_its_budget(room, tmp_path):
    full = casual3d.write_package(room, tmp_path / "full")
    assert full["color_quality"] == 90 and full["lossy_normals"] is False
    budget_kb = full["total_bytes"] * 9 // 10 // 1024
    fitted = casual3d.write_package(room, tmp_path / "fitted", max_kb=budget_kb)
    assert fitted["total_bytes"] <= budget_kb * 1024
    assert fitted["lossy_normals"] or fitted["color_quality"] < 90
    casual3d.read(tmp_path / "fitted")
    with pytest.raises(ValueError, match="does not fit in 1.0 KB: the smallest was"):
        casual3d.write_package(room, tmp_path / "tiny", max_kb=1)
    assert not (tmp_path / "tiny").exists()
    with pytest.raises(ValueError, match="max_kb 0: expected a positive whole number"):
        casual3d.write_package(room, tmp_path / "zero", max_kb=0)


def test_max_kb_takes_numpy_integers_and_checks_min_quality(room, tmp_path):
    fitted = casual3d.write_package(room, tmp_path / "np", max_kb=np.int64(10**6))
    assert fitted["color_quality"] == 90
    for bad in (120, -1, "80", True):
        with pytest.raises(ValueError, match="min_quality .*: expected a number in \\[0, 100\\]"):
            casual3d.write_package(room, tmp_path / "q", max_kb=100, min_quality=bad)
    with pytest.raises(ValueError, match="max_kb .*: expected a positive whole number"):
        casual3d.write_package(room, tmp_path / "big", max_kb=2**60)
