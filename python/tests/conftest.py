"""Shared fixtures: the source tree, the built `casual3d` program, and
panoramas made in numpy."""

import os
import pathlib
import subprocess

import numpy as np
import pytest

import casual3d

SOURCE_DIR = pathlib.Path(os.environ.get("CASUAL3D_SOURCE_DIR",
                                         pathlib.Path(__file__).resolve().parents[2]))
VECTORS = SOURCE_DIR / "spec" / "vectors"


@pytest.fixture
def cli():
    """Runs the built `casual3d` program (path in CASUAL3D_CLI); skips without it."""
    path = os.environ.get("CASUAL3D_CLI", "")
    if not path or not os.path.exists(path):
        pytest.skip("the casual3d program is not built (CASUAL3D_CLI unset)")

    def run(*args):
        return subprocess.run([path, *map(str, args)], capture_output=True, text=True)

    return run


def make_room(width=128, height=64):
    """A synthetic panorama: a room (walls 2-3 m away) with a box at 1 m in
    front of one wall, back nodes of the wall behind the box, smooth colours,
    unlit sky above 60 degrees of latitude; linked by link_neighbours."""
    pano = casual3d.Panorama.empty(width, height)
    y, x = np.mgrid[0:height, 0:width]
    lon = ((x + 0.5) / width - 0.5) * 2 * np.pi
    lat = (0.5 - (y + 0.5) / height) * np.pi
    direction = np.stack([np.cos(lat) * np.sin(lon), np.sin(lat),
                          -np.cos(lat) * np.cos(lon)], axis=-1).astype(np.float32)
    wall = (2.5 + 0.5 * np.sin(3 * lon) * np.cos(lat)).astype(np.float32)
    box = (np.abs(lon) < 0.5) & (np.abs(lat) < 0.4)
    sky = lat > np.pi / 3

    front, back = pano.front, pano.back
    front.depth[:] = np.where(box, np.float32(1.0) + 0.05 * lon.astype(np.float32) ** 2, wall)
    front.normals[:] = np.where(sky[..., None], 0.0, -direction)
    # Photo-like colours: a smooth brightness pattern, the box brighter and
    # tinted blue, the walls tinted warm.
    brightness = 110 + 60 * np.sin(4 * lon) * np.cos(2 * lat) + np.where(box, 40, 0)
    tint = np.where(box[..., None], [0.85, 0.95, 1.1], [1.1, 1.0, 0.85])
    front.color[:] = np.clip(brightness[..., None] * tint, 0, 255).astype(np.uint8)
    back.depth[:] = np.where(box, wall, np.nan)
    back.normals[:] = np.where(box[..., None], -direction, np.nan)
    back.color[:] = np.where(box[..., None], front.color // 2, 0).astype(np.uint8)
    back.labels[:] = np.where(box, casual3d.LABEL_B, 0).astype(np.uint8)
    pano.view_hints = {"yaw_deg": 10.0, "pitch_deg": 0.0, "fov_deg": 70.0,
                       "content_yaw_deg": [-180.0, 180.0], "content_pitch_deg": [-90.0, 90.0],
                       "volume_radius": 0.05, "metric": True}
    return casual3d.link_neighbours(pano)


@pytest.fixture
def room():
    return make_room()
