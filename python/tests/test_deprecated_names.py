"""The earlier names spelt "colour" (python/README.md, "Deprecated names")
still work beside the current ones, and warn."""

import numpy as np
import pytest

import casual3d


def small_panorama():
    pano = casual3d.Panorama.empty(32, 16)
    pano.front.depth[:] = 2.0
    pano.front.normals[:] = 0.0
    pano.front.color[:] = [90, 160, 70]
    return casual3d.link_neighbours(pano)


def test_deprecated_layer_field():
    layer = casual3d.Layer.empty(4, 2)
    with pytest.deprecated_call():
        assert layer.colour is layer.color
    with pytest.deprecated_call():
        layer.colour = np.full((2, 4, 3), 7, np.uint8)
    assert np.all(layer.color == 7)
    fields = dict(depth=layer.depth, normals=layer.normals, labels=layer.labels,
                  links=layer.links)
    with pytest.deprecated_call():
        old = casual3d.Layer(colour=layer.color, **fields)
    assert old.color is layer.color


def test_deprecated_mesh_field():
    mesh = casual3d.build_mesh(small_panorama())
    with pytest.deprecated_call():
        assert mesh.colours is mesh.colors


def test_deprecated_atlas_function():
    pano = small_panorama()
    with pytest.deprecated_call():
        old = casual3d.colour_atlas(pano)
    assert np.array_equal(old, casual3d.color_atlas(pano))


def test_deprecated_package_options(tmp_path):
    pano = small_panorama()
    casual3d.write_package(pano, tmp_path / "new.c3d", color_quality=60, color_method=2)
    with pytest.deprecated_call():
        casual3d.write_package(pano, tmp_path / "old.c3d", colour_quality=60, colour_method=2)
    assert (tmp_path / "new.c3d").read_bytes() == (tmp_path / "old.c3d").read_bytes()
