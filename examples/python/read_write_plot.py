"""casual3d from Python: read a 3D photo and print its layers, write a new
package from a synthetic numpy panorama, and save a picture of a depth layer.

    python3 read_write_plot.py PACKAGE [-o OUT_DIR]

PACKAGE is a package folder, a .c3d file or a master .exr file. OUT_DIR
(default: ./casual3d-example) receives synthetic.c3d and depth.png. The plot
uses matplotlib when it is installed (Debian: python3-matplotlib), otherwise
a grey-scale PNG written with the standard library.
"""

import argparse
import pathlib
import struct
import zlib

import numpy as np

import casual3d


def print_layers(path):
    package = casual3d.Package(path)
    print(f"{path}: {package.manifest['width']}x{package.manifest['height']}, "
          f"{package.num_levels} levels, casual3d {package.manifest['version']} package")
    for level in range(package.num_levels):
        pano = package.read(level)
        for name, layer in zip(("front", "back"), pano.layers):
            present = layer.present
            if not present.any():
                print(f"  level {level} {name}: no nodes")
                continue
            depth = layer.depth[present]
            print(f"  level {level} {name}: {present.sum()} nodes, depth "
                  f"{depth.min():.2f}-{depth.max():.2f} m, mean colour "
                  f"{layer.color[present].mean(axis=0).round().astype(int).tolist()}")
    return package.read(0)


def synthetic_panorama(width=256, height=128):
    """A sphere of radius 3 m around the viewpoint with a 1 m box in front,
    the wall behind the box in the back layer."""
    pano = casual3d.Panorama.empty(width, height)
    y, x = np.mgrid[0:height, 0:width]
    lon = ((x + 0.5) / width - 0.5) * 2 * np.pi
    lat = (0.5 - (y + 0.5) / height) * np.pi
    inward = -np.stack([np.cos(lat) * np.sin(lon), np.sin(lat), -np.cos(lat) * np.cos(lon)], -1)
    box = (np.abs(lon) < 0.4) & (np.abs(lat) < 0.3)
    grey = (120 + 60 * np.sin(3 * lon) * np.cos(lat)).astype(np.uint8)

    pano.front.depth[:] = np.where(box, 1.0, 3.0)
    pano.front.normals[:] = inward
    pano.front.color[:] = grey[..., None]
    pano.front.color[box] = [200, 80, 60]
    pano.back.depth[box] = 3.0
    pano.back.normals[box] = inward[box]
    pano.back.color[box] = grey[box][:, None]
    pano.back.labels[box] = casual3d.LABEL_B
    return casual3d.link_neighbours(pano)


def save_depth_picture(depth, path):
    """Near is bright, far is dark, absent nodes black."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        near, far = np.nanmin(depth), np.nanmax(depth)
        grey = np.where(np.isnan(depth), 0,
                        255 - 200 * (depth - near) / max(far - near, 1e-9)).astype(np.uint8)
        rows = b"".join(b"\x00" + row.tobytes() for row in grey)
        chunk = lambda kind, data: (struct.pack(">I", len(data)) + kind + data +
                                    struct.pack(">I", zlib.crc32(kind + data)))
        path.write_bytes(b"\x89PNG\r\n\x1a\n" +
                         chunk(b"IHDR", struct.pack(">IIBBBBB", grey.shape[1], grey.shape[0],
                                                    8, 0, 0, 0, 0)) +
                         chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))
        print(f"wrote {path} (grey scale; install python3-matplotlib for a colour plot)")
        return
    fig, ax = plt.subplots(figsize=(8, 4))
    image = ax.imshow(depth, cmap="viridis_r")
    fig.colorbar(image, ax=ax, label="depth (m)")
    ax.set_title("front layer depth")
    fig.savefig(path, dpi=100)
    plt.close(fig)
    print(f"wrote {path}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("package", help="package folder, .c3d or master .exr file")
    parser.add_argument("-o", "--out", default="casual3d-example", help="output folder")
    args = parser.parse_args()
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    print(f"casual3d {casual3d.__version__}")
    pano = print_layers(args.package)

    synthetic = synthetic_panorama()
    sizes = casual3d.write_package(synthetic, out / "synthetic.c3d")
    levels = casual3d.validate(out / "synthetic.c3d")
    print(f"wrote {out / 'synthetic.c3d'}: {sizes['total_bytes']} bytes, "
          f"{levels[0]['front_nodes']} front and {levels[0]['back_nodes']} back nodes")
    mesh = casual3d.build_mesh(casual3d.read(out / "synthetic.c3d"), simplify=True)
    print(f"its simplified mesh: {mesh.num_vertices} vertices, {mesh.num_triangles} triangles")

    save_depth_picture(pano.front.depth, out / "depth.png")


if __name__ == "__main__":
    main()
