"""examples/python/read_write_plot.py runs and does what it says."""

import importlib.util
import os
import struct
import subprocess
import sys
import zlib

import casual3d
from conftest import SOURCE_DIR, VECTORS


def test_example_script(tmp_path, cli):
    script = SOURCE_DIR / "examples" / "python" / "read_write_plot.py"
    out = subprocess.run([sys.executable, script, VECTORS / "two-layer-64x32.c3d",
                          "-o", tmp_path], capture_output=True, text=True, env=os.environ)
    assert out.returncode == 0, out.stderr
    assert "level 0 back: 120 nodes" in out.stdout
    assert "level 1 front: 512 nodes" in out.stdout
    written = tmp_path / "synthetic.c3d"
    assert cli("validate", written).returncode == 0
    pano = casual3d.read(written)
    assert (pano.width, pano.height) == (256, 128)
    assert pano.back.present.sum() > 0
    png = (tmp_path / "depth.png").read_bytes()
    assert png.startswith(b"\x89PNG\r\n\x1a\n")
    if importlib.util.find_spec("matplotlib") is None:  # The standard-library writer.
        width, height = struct.unpack(">II", png[16:24])
        assert (width, height) == (64, 32)
        idat = png.index(b"IDAT")
        length = struct.unpack(">I", png[idat - 4:idat])[0]
        rows = zlib.decompress(png[idat + 4:idat + 4 + length])
        assert len(rows) == height * (width + 1)
