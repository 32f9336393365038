"""casual3d: read, check, mesh and write 3D photos from Python.

A 3D photo is a two-layer panorama (spec/data-model.md): an equirectangular
grid of H x W pixels in which each pixel holds up to two nodes, front and
back. Here a panorama is a :class:`Panorama` of two :class:`Layer` objects
whose fields are numpy arrays (see :class:`Layer` for their types).

Reading::

    pano = casual3d.read("photo.c3d")          # package folder, .c3d or master .exr
    pkg = casual3d.Package("web/")             # every level, and the manifest
    casual3d.validate("web/")                  # what `casual3d validate` checks

Meshes and export::

    mesh = casual3d.build_mesh(pano, simplify=True)
    casual3d.export_glb(pano, "photo.glb", draco=True)

Writing::

    casual3d.write_package(pano, "out/web")    # a package folder
    casual3d.write_package(pano, "out.c3d")    # the single-file form
    casual3d.write_master(pano, "master.exr")  # lossless OpenEXR

Failures raise :class:`FormatError` (a ValueError) for malformed, unsupported
or inconsistent data, ValueError for arguments out of range and OSError when
the operating system refuses a read or write; messages name the file.
"""

import functools as _functools
import json as _json
import numbers as _numbers
import operator as _operator
import os as _os
import warnings as _warnings
from dataclasses import dataclass, field
from typing import List, Optional

import numpy as np

from . import _casual3d
from ._casual3d import FormatError, __version__

__all__ = [
    "FormatError", "Layer", "Panorama", "Package", "Mesh", "read", "read_manifest",
    "validate", "build_mesh", "color_atlas", "colour_atlas", "write_package", "write_master",
    "export_glb",
    "link_neighbours", "RIGHT", "DOWN", "LEFT", "UP", "NO_LINK", "LINK_FRONT", "LINK_BACK",
    "LABEL_F", "LABEL_B", "__version__",
]

# Directions of Layer.links' last axis (format/two_layer.h Direction).
RIGHT, DOWN, LEFT, UP = 0, 1, 2, 3
# Values of Layer.links: which node of the neighbouring pixel a node links to.
NO_LINK, LINK_FRONT, LINK_BACK = 0, 1, 2
# Values of Layer.labels (paper Sec. 4.4.3): F from the front stitch, B from
# the back stitch or relabelled by colour fringe removal.
LABEL_F, LABEL_B = 0, 1

_EXR_MAGIC = b"\x76\x2f\x31\x01"


# The earlier names spelt "colour" keep working, deprecated (python/README.md,
# "Deprecated names"): each use warns with DeprecationWarning.
def _warn_renamed(old: str, new: str) -> None:
    _warnings.warn(f"casual3d: {old} is deprecated; use {new}", DeprecationWarning, stacklevel=3)


def _renamed_fields(renamed: dict):
    """Class decorator: the fields' former names (old -> new) as constructor
    keywords and attributes that warn and use the new field."""

    def decorate(cls):
        init = cls.__init__

        @_functools.wraps(init)
        def __init__(self, *args, **kwargs):
            for old, new in renamed.items():
                if old in kwargs:
                    _warn_renamed(f"{cls.__name__}({old}=...)", f"{new}=")
                    kwargs[new] = kwargs.pop(old)
            init(self, *args, **kwargs)

        def alias(old, new):
            def get(self):
                _warn_renamed(f"{cls.__name__}.{old}", new)
                return getattr(self, new)

            def put(self, value):
                _warn_renamed(f"{cls.__name__}.{old}", new)
                setattr(self, new, value)

            return property(get, put, doc=f"Deprecated name of {new}.")

        cls.__init__ = __init__
        for old, new in renamed.items():
            setattr(cls, old, alias(old, new))
        return cls

    return decorate


# write_package's options under their former names.
_RENAMED_PACKAGE_OPTIONS = {"colour_quality": "color_quality", "colour_method": "color_method"}


@_renamed_fields({"colour": "color"})
@dataclass
class Layer:
    """One layer (front or back) of a panorama of H x W pixels.

    Attributes:
        color: uint8 (H, W, 3), sRGB; 0 where the node is absent.
        depth: float32 (H, W), metres from the frame centre along the pixel's
            ray (> 0); NaN where the pixel has no node of this layer. A node
            exists exactly where depth is not NaN.
        normals: float32 (H, W, 3), unit normals in the panorama frame
            (+X right, +Y up, -Z forward), (0, 0, 0) for unlit nodes such as
            the sky; NaN where absent.
        labels: uint8 (H, W), LABEL_F (0) or LABEL_B (1); 0 where absent.
        links: uint8 (H, W, 4), per direction RIGHT, DOWN, LEFT, UP (columns
            wrap at the +-180 degree seam, rows do not): NO_LINK (0), or the
            neighbouring pixel's node this node connects to, LINK_FRONT (1) or
            LINK_BACK (2). Links must be mutual; triangles exist exactly where
            nodes are linked.
    """

    color: np.ndarray
    depth: np.ndarray
    normals: np.ndarray
    labels: np.ndarray
    links: np.ndarray

    @classmethod
    def empty(cls, width: int, height: int) -> "Layer":
        """A layer of width x height pixels without nodes (all fields as absent)."""
        return cls(
            color=np.zeros((height, width, 3), np.uint8),
            depth=np.full((height, width), np.nan, np.float32),
            normals=np.full((height, width, 3), np.nan, np.float32),
            labels=np.zeros((height, width), np.uint8),
            links=np.zeros((height, width, 4), np.uint8),
        )

    @property
    def present(self) -> np.ndarray:
        """bool (H, W): where this layer has a node."""
        return ~np.isnan(self.depth)

    def packed_links(self) -> np.ndarray:
        """uint8 (H, W): the 4 links packed as stored (bits 2d..2d+1: direction d)."""
        links = np.asarray(self.links, np.uint8)
        return (links[..., 0] | links[..., 1] << 2 | links[..., 2] << 4 | links[..., 3] << 6)


@dataclass
class Panorama:
    """A two-layer panorama: the data of a 3D photo at one level of detail.

    Attributes:
        front, back: the two layers (:class:`Layer`), of the same size.
        centre: float64 (3,), the frame's centre in the capture's world.
        rotation: float64 (3, 3), row-major, world to panorama frame:
            p_panorama = rotation @ (p_world - centre).
        view_hints: how to look at the 3D photo (the manifest's "view" object,
            spec/package.md Sec. 3.1: yaw_deg, pitch_deg, fov_deg,
            content_yaw_deg, content_pitch_deg, volume_radius, metric), or None.
    """

    front: Layer
    back: Layer
    centre: np.ndarray = field(default_factory=lambda: np.zeros(3))
    rotation: np.ndarray = field(default_factory=lambda: np.eye(3))
    view_hints: Optional[dict] = None

    @classmethod
    def empty(cls, width: int, height: int) -> "Panorama":
        """A panorama of width x height pixels without nodes.

        Nodes are added by setting depth (and colour, normals, labels: back
        nodes are usually LABEL_B); link_neighbours() then links them.
        """
        return cls(Layer.empty(width, height), Layer.empty(width, height))

    @property
    def width(self) -> int:
        return self.front.depth.shape[1]

    @property
    def height(self) -> int:
        return self.front.depth.shape[0]

    @property
    def layers(self):
        """(front, back)."""
        return (self.front, self.back)

    @classmethod
    def _from_native(cls, d: dict) -> "Panorama":
        front, back = (Layer(**layer) for layer in d["layers"])
        hints = d["view_hints"]
        return cls(front, back, d["centre"], d["rotation"],
                   _json.loads(hints) if hints is not None else None)


@_renamed_fields({"colours": "colors"})
@dataclass
class Mesh:
    """A triangle mesh of a panorama (spec/mesh.md) with its colour atlas.

    Attributes:
        positions: float32 (N, 3), panorama frame, metres; the viewpoint is
            the origin.
        normals: float32 (N, 3), unit, or (0, 0, 0) where unlit.
        uvs: float32 (N, 2) into `atlas`: u = (x + 0.5) / W, v over the atlas
            height; seam copies of column-0 nodes have u > 1 (textures repeat
            horizontally).
        colors: uint8 (N, 3), each vertex's node colour (sRGB).
        indices: uint32 (T, 3), counter-clockwise seen from the centre.
        atlas: uint8 (2H, W, 3), the front layer's colours above the back
            layer's, each filled with the other layer's colour where its own
            node is absent (format/color_atlas.h).
        error_bound: simplified meshes: the largest relative depth error of a
            merged block (0.01 = 1 %); None for the full mesh.
        full_triangles: simplified meshes: triangles of the full mesh.
        budget_met: simplified meshes: False if max_relative_error left more
            than max_triangles triangles.
    """

    positions: np.ndarray
    normals: np.ndarray
    uvs: np.ndarray
    colors: np.ndarray
    indices: np.ndarray
    atlas: np.ndarray
    error_bound: Optional[float] = None
    full_triangles: Optional[int] = None
    merged_blocks: Optional[int] = None
    budget_met: Optional[bool] = None

    @property
    def num_vertices(self) -> int:
        return self.positions.shape[0]

    @property
    def num_triangles(self) -> int:
        return self.indices.shape[0]


class Package:
    """A package (folder or .c3d file) opened for reading, level by level.

    Attributes:
        path: as given.
        manifest: manifest.json as a dict (spec/package.md Sec. 3).
        num_levels: levels of detail; level 0 is the full resolution, each
            next level smaller by a power of two: (W >> k) x (H >> k) in 1.x
            packages, possibly smaller from 2.0, which may leave out
            halvings (`manifest["levels"]` gives the sizes).
    """

    def __init__(self, path):
        self.path = _os.fspath(path)
        self._native = _casual3d._Package(self.path)
        self.manifest = _json.loads(self._native.manifest_json)
        self.num_levels = self._native.num_levels

    def read(self, level: int = 0, *, threads: int = 0,
             verify_checksums: bool = True) -> Panorama:
        """The panorama of `level` (threads 0: all cores)."""
        return Panorama._from_native(self._native.read_level(level, threads, verify_checksums))

    def levels(self, *, threads: int = 0) -> List[Panorama]:
        """Every level, finest first."""
        return [self.read(level, threads=threads) for level in range(self.num_levels)]

    def __repr__(self):
        return (f"casual3d.Package({self.path!r}: {self.manifest['width']}x"
                f"{self.manifest['height']}, {self.num_levels} levels)")


def _is_master_file(path: str) -> bool:
    if _os.path.isdir(path):
        return False
    try:
        with open(path, "rb") as f:
            return f.read(4) == _EXR_MAGIC
    except OSError:
        return False  # The package reader names the problem.


def read(path, level: int = 0, *, threads: int = 0,
         verify_checksums: bool = True) -> Panorama:
    """Reads a 3D photo: a package folder, a .c3d file or a master file (.exr).

    Recognised by content, not by name. `level` picks a package's level of
    detail (a master file has level 0 only); `threads` decode tiles (0: all
    cores); `verify_checksums` checks every file's SHA-256 against the
    manifest. Raises FormatError naming the file.
    """
    path = _os.fspath(path)
    if _is_master_file(path):
        if level != 0:
            raise ValueError(f"{path}: a master file has one level only (level 0)")
        return Panorama._from_native(_casual3d._read_master(path))
    return Package(path).read(level, threads=threads, verify_checksums=verify_checksums)


def read_manifest(path) -> dict:
    """The manifest.json of a package (folder or .c3d) as a dict."""
    return Package(path).manifest


def validate(path, *, threads: int = 0) -> List[dict]:
    """Checks a package completely, as `casual3d validate` does.

    The manifest, every file's size and SHA-256, every tile image and every
    level's panorama. Returns one dict per level (level, width, height,
    front_nodes, back_nodes, files); raises FormatError with the message
    `casual3d validate` prints for the first problem.
    """
    return _casual3d._validate(_os.fspath(path), threads)


def _mesh_choice(simplify, max_triangles, max_relative_error, include_back_layer, threads):
    choice = _casual3d._MeshChoice()
    choice.simplify = simplify
    if max_triangles is not None:
        choice.max_triangles = max_triangles
    if max_relative_error is not None:
        choice.max_relative_error = max_relative_error
    choice.include_back_layer = include_back_layer
    choice.num_threads = threads
    return choice


def build_mesh(pano: Panorama, *, simplify: bool = False, max_triangles: Optional[int] = None,
               max_relative_error: Optional[float] = None, include_back_layer: bool = True,
               threads: int = 0) -> Mesh:
    """The triangle mesh of `pano` with its colour atlas.

    simplify False: the full mesh of spec/mesh.md (format/mesh_builder.h),
    one vertex per linked node. True: the grid-aware simplification
    (format/mesh_simplify.h): the finest mesh with at most `max_triangles`
    triangles (default 1,000,000; 0: no budget) and never coarser than
    `max_relative_error` (default 0.01) allows. include_back_layer False
    builds a front-only mesh. The panorama is validated first (FormatError).
    """
    choice = _mesh_choice(simplify, max_triangles, max_relative_error, include_back_layer,
                          threads)
    return Mesh(**_casual3d._build_mesh(pano, choice))


def color_atlas(pano: Panorama) -> np.ndarray:
    """uint8 (2H, W, 3): the atlas that Mesh.uvs address (see Mesh.atlas)."""
    return _casual3d._color_atlas(pano)


def colour_atlas(pano: Panorama) -> np.ndarray:
    """Deprecated name of :func:`color_atlas`."""
    _warn_renamed("colour_atlas()", "color_atlas()")
    return color_atlas(pano)


def _set_options(options, kwargs, what):
    for name, value in kwargs.items():
        if name.startswith("_") or not hasattr(options, name):
            raise TypeError(f"{what}: unknown option {name!r}")
        setattr(options, name, value)
    return options


def write_package(pano: Panorama, path, *, max_kb: Optional[int] = None, min_quality: float = 75,
                  **options) -> dict:
    """Writes `pano` as a package: a folder, or one .c3d file if `path` ends in .c3d.

    Written atomically; an existing folder is replaced only if it is empty or
    holds a package. Options (encoder/package_writer.h, defaults in brackets):
    tile_size [512], levels [0: automatic], omit_level_width [0: every
    level; 2048 leaves out the level of 1025..2048 pixels wide, package
    version 2.0, as `casual3d encode` does], color_quality [90] (lossy WebP,
    0..100), color_method [3], lossless_effort [25], lossless_method [1],
    depth_bits [12], normal_bits [8], lossy_normals [False],
    normal_mean_error_deg [2.5], normal_p99_error_deg [8.0], threads [0: all
    cores], generator. Colour is lossy; depth (quantized to depth_bits),
    normals (normal_bits), labels and links are stored losslessly, but with
    lossy_normals the normals are lossy images whose tiles keep the two error
    bounds (package version 1.2). With `max_kb` the whole package fits in
    that many KB (1024 bytes), as `casual3d encode --max-kb` does: lossy
    normals first, then the highest colour quality down to `min_quality` that
    fits (the tiles and manifest; a .c3d adds its small index); a ValueError
    names the smallest size reached when nothing fits.
    Returns the sizes written and the colour quality and normals used.
    """
    if max_kb is not None:
        try:
            kb = _operator.index(max_kb)
        except TypeError:
            kb = 0
        if isinstance(max_kb, bool) or not 1 <= kb <= 2**53 // 1024:
            raise ValueError(f"max_kb {max_kb!r}: expected a positive whole number of KB, or None")
        max_kb = kb
    if isinstance(min_quality, bool) or not isinstance(min_quality, _numbers.Real) \
            or not 0 <= min_quality <= 100:
        raise ValueError(f"min_quality {min_quality!r}: expected a number in [0, 100]")
    path = _os.fspath(path)
    native = _casual3d._PackageOptions()
    native.generator = f"casual3d {__version__}"
    for old, new in _RENAMED_PACKAGE_OPTIONS.items():
        if old in options:
            _warn_renamed(f"write_package({old}=...)", f"{new}=")
            options[new] = options.pop(old)
    _set_options(native, options, "write_package")
    return _casual3d._write_package(pano, path, path.lower().endswith(".c3d"), native,
                                    (max_kb or 0) * 1024, float(min_quality))


def write_master(pano: Panorama, path) -> None:
    """Writes `pano` as a master file (OpenEXR, lossless: reads back bit for bit)."""
    _casual3d._write_master(pano, _os.fspath(path))


def export_glb(package_or_panorama, path, *, draco: bool = False, simplify: bool = True,
               max_triangles: Optional[int] = None, max_relative_error: Optional[float] = None,
               level: int = 0, texture: str = "jpeg", threads: int = 0, **options) -> dict:
    """Writes a 3D photo as binary glTF (GLB), as `casual3d export` does.

    `package_or_panorama` is a Panorama, a Package or a path that read()
    accepts (with `level`). The mesh is simplified as build_mesh does unless
    simplify is False; `texture` is "jpeg" or "png". Further options
    (encoder/gltf_export.h): jpeg_quality [90], max_texture_size [8192],
    normals [True], unlit [True], double_sided [False], draco_position_bits
    [0: automatic], draco_normal_bits [10], draco_texcoord_bits [14],
    draco_compression_level [6]. Returns the figures of the written file
    (num_vertices, num_triangles, texture_width, texture_height, file_bytes, ...).
    """
    if isinstance(package_or_panorama, Panorama):
        pano = package_or_panorama
    elif isinstance(package_or_panorama, Package):
        pano = package_or_panorama.read(level, threads=threads)
    else:
        pano = read(package_or_panorama, level, threads=threads)
    if texture not in ("jpeg", "png"):
        raise ValueError(f"texture {texture!r}: expected 'jpeg' or 'png'")
    native = _casual3d._GltfExportOptions()
    native.texture_format = getattr(_casual3d._TextureFormat, texture)
    native.draco = draco
    _set_options(native, options, "export_glb")
    choice = _mesh_choice(simplify, max_triangles, max_relative_error, True, threads)
    return _casual3d._export_glb(pano, _os.fspath(path), choice, native)


def link_neighbours(pano: Panorama, min_depth_ratio: float = 0.75) -> Panorama:
    """Recomputes every link of `pano` in place from depths alone, and returns it.

    For each pair of neighbouring pixels (right and down; columns wrap), the
    pair of nodes with the most similar depth is linked if min(d) / max(d) >
    min_depth_ratio; when those are of the same layer, the other two nodes are
    linked too under the same test (links never cross). Candidates are ranked
    front-front, front-back, back-front, back-back on ties. This is the rule
    of the paper's Sec. 4.4.3 step 2 without its colour terms: enough for
    synthetic panoramas made in numpy.
    """
    layers = pano.layers
    for layer in layers:
        layer.links = np.zeros(layer.depth.shape + (4,), np.uint8)
    depth = [np.asarray(layer.depth, np.float32) for layer in layers]
    for direction, shift in ((RIGHT, lambda a: np.roll(a, -1, axis=1)),
                             (DOWN, lambda a: a[1:])):
        rows = depth[0].shape[0] - (1 if direction == DOWN else 0)
        if direction == RIGHT and depth[0].shape[1] < 2:
            continue
        here = [d[:rows] for d in depth]
        there = [shift(d) for d in depth]
        # ratio[k] of candidate pair k = (a, b): a here, b there; -inf if absent.
        pairs = [(0, 0), (0, 1), (1, 0), (1, 1)]
        with np.errstate(invalid="ignore"):
            ratio = np.stack([
                np.where(np.isnan(here[a]) | np.isnan(there[b]), -np.inf,
                         np.minimum(here[a], there[b]) / np.maximum(here[a], there[b]))
                for a, b in pairs]).astype(np.float32)
        best = np.argmax(ratio, axis=0)
        best_ratio = np.take_along_axis(ratio, best[None], 0)[0]
        linked = best_ratio > np.float32(min_depth_ratio)
        for k, (a, b) in enumerate(pairs):
            _connect(layers, direction, rows, linked & (best == k), a, b)
            if a == b:  # The pair that does not cross it.
                other = pairs.index((1 - a, 1 - b))
                _connect(layers, direction, rows,
                         linked & (best == k) & (ratio[other] > np.float32(min_depth_ratio)),
                         1 - a, 1 - b)
    return pano


def _connect(layers, direction, rows, mask, a, b):
    """Links node a of each pixel in `mask` to node b of its neighbour in `direction`."""
    opposite = (direction + 2) % 4
    layers[a].links[:rows, :, direction][mask] = LINK_FRONT if b == 0 else LINK_BACK
    there = np.zeros(layers[b].depth.shape, bool)
    if direction == RIGHT:
        there = np.roll(mask, 1, axis=1)
    else:
        there[1:] = mask
    layers[b].links[..., opposite][there] = LINK_FRONT if a == 0 else LINK_BACK
