"""Type stubs of raylab's native module (re-exported by the ``raylab`` package)."""

import os
import pathlib
from typing import Any, Dict, List, Literal, Optional, Sequence, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

__version__: str

_Path = Union[str, os.PathLike]
_Vec3 = Tuple[float, float, float]
_Floats = npt.ArrayLike
_AccelName = Literal["none", "bvh", "bvh-median", "bvh-midpoint", "aabb", "grid", "lbvh", "lbvh-ploc", "kdtree", "sphere-bvh", "sbvh"]

class RaylabError(ValueError):
    """An error about raylab's input (scene, mesh, image, ray file) or a structure failing
    validation. ``str(e)`` is raylab's ``file:line: field: message``; for scene errors the
    ``file``, ``line`` (or None) and ``field`` (or None) attributes hold its parts."""

    file: str
    line: Optional[int]
    field: Optional[str]

def render(
    scene_path: Optional[_Path] = None,
    *,
    spp: Optional[int] = ...,
    width: Optional[int] = ...,
    height: Optional[int] = ...,
    max_depth: Optional[int] = ...,
    sampler: Optional[str] = ...,
    integrator: Optional[str] = ...,
    light_sampling: Optional[str] = ...,
    light_cells: Optional[int] = ...,
    mis_heuristic: Optional[str] = ...,
    accel: Optional[str] = ...,
    seed: Optional[int] = ...,
    filter: Optional[str] = ...,
    threads: Optional[int] = ...,
) -> npt.NDArray[np.float32]:
    """Renders a scene file (or bare mesh; the embedded default scene when None) and returns
    the (H, W, 3) float32 linear image, row 0 at the top: the values ``raylab render -o x.pfm``
    writes (PFM stores rows bottom-up). Overrides are named like the CLI's flags. The GIL is
    released while rendering; Ctrl-C raises KeyboardInterrupt."""

def trace(
    mesh_or_scene_path: _Path,
    origins: _Floats,
    directions: _Floats,
    *,
    tmin: Optional[Union[float, _Floats]] = None,
    tmax: Optional[Union[float, _Floats]] = None,
    accel: Optional[_AccelName] = None,
    any_hit: bool = False,
    threads: Optional[int] = None,
) -> Dict[str, np.ndarray]:
    """Traces N rays through the geometry of a scene or mesh file (structure ``accel``,
    default "bvh", built as ``raylab trace`` builds it), in parallel over the rays.

    ``origins`` and ``directions`` are (N, 3) float arrays (float32 C-contiguous arrays are
    read in place; other float arrays are converted); ``tmin``/``tmax`` a float or an (N,)
    array (default 0 and inf). Hits count with ``t`` in ``(tmin, tmax]``.

    Closest hit returns ``t`` (float32, inf on a miss), ``prim`` (int64, -1 on a miss),
    ``u``, ``v`` (the primitive's surface parameters, barycentrics for triangles);
    ``any_hit=True`` returns ``hit`` (bool). Both return ``nodes_visited`` and ``prim_tests``
    (int64, per ray). A wrong dtype or shape raises ValueError."""

def build(
    source: Union[_Path, _Floats],
    indices: Optional[npt.ArrayLike] = None,
    *,
    accel: _AccelName = "bvh",
    threads: Optional[int] = None,
) -> Structure:
    """Builds a structure over a scene or mesh file, or over a triangle mesh given as (V, 3)
    float vertices and (F, 3) integer indices (primitive i is row i of ``indices``)."""

def load_mesh(path: _Path) -> Tuple[npt.NDArray[np.float32], npt.NDArray[np.int64]]:
    """The triangles of a scene or mesh file as (V, 3) float32 vertices and (F, 3) int64
    indices; for files of meshes only, row i of the indices is primitive i."""

def accels() -> List[str]:
    """The structure names ``accel=`` accepts, the brute-force oracle ``none`` first."""

def bench(
    scenes: Optional[Union[_Path, Sequence[_Path]]] = None,
    *,
    accels: Optional[Union[str, Sequence[str]]] = None,
    rays: Optional[Union[str, Sequence[str]]] = None,
    resolution: int = 256,
    repeats: int = 3,
    threads: Optional[int] = None,
    oracle_limit: int = 20000,
    seed: int = 1,
) -> Dict[str, Any]:
    """``raylab bench --json`` as a dict: every structure (default "all") on the same primary,
    diffuse and shadow rays of each scene, medians after a warm-up, every answer checked
    against an oracle (a mismatch raises RaylabError). ``pandas.json_normalize(r["results"])``
    gives one row per scene and structure."""

def compare(a: Union[_Path, _Floats], b: Union[_Path, _Floats], *, exclude_bright: Optional[float] = None) -> Dict[str, Any]:
    """``raylab compare --json``'s figures for two images (paths or (H, W, 3) arrays; ``b`` is
    the reference): mse, rmse, rel_mse, psnr_db (None when identical), max_abs, pixels, excluded."""

def converge(
    scene_path: _Path,
    *,
    reference: Optional[Union[_Path, _Floats]] = None,
    reference_spp: int = 4096,
    strategies: Optional[Union[str, Sequence[str]]] = None,
    spp: Optional[Sequence[int]] = None,
    exclude_bright: Optional[float] = None,
    **overrides: Any,
) -> Dict[str, Any]:
    """``raylab converge``'s study: error against the reference (rendered with mis at
    ``reference_spp`` and another seed when None) per light-sampling strategy and spp.
    Returns width, height, ``points`` (dicts of strategy, spp, seconds, mse, rmse, rel_mse),
    ``slopes`` (least-squares slope of ln MSE against ln spp per strategy) and ``reference``."""

class Structure:
    """An acceleration structure over a mesh or a scene's geometry (see :func:`build`)."""

    @property
    def accel(self) -> str: ...
    @property
    def primitives(self) -> int: ...
    @property
    def bounds(self) -> Tuple[_Vec3, _Vec3]: ...
    @property
    def stats(self) -> Dict[str, Any]:
        """Build statistics: name, build_ms, primitives, interior_nodes, leaves, max_depth,
        references, leaf_histogram, sah_cost, memory_bytes, notes."""
    def validate(self) -> None:
        """Checks the structure's invariants; raises RaylabError when one is broken."""
    def triangles(self) -> Tuple[npt.NDArray[np.float32], npt.NDArray[np.int64]]: ...
    def trace(
        self,
        origins: _Floats,
        directions: _Floats,
        *,
        tmin: Optional[Union[float, _Floats]] = None,
        tmax: Optional[Union[float, _Floats]] = None,
        any_hit: bool = False,
        threads: Optional[int] = None,
    ) -> Dict[str, np.ndarray]:
        """As :func:`trace`, through this structure."""

class Scene:
    """A scene loaded from any file raylab reads (the default scene when ``path`` is None),
    with the overrides ``raylab render`` takes as flags."""

    def __init__(self, path: Optional[_Path] = None, **overrides: Any) -> None: ...
    @property
    def path(self) -> Optional[pathlib.Path]: ...
    @property
    def settings(self) -> Dict[str, Any]:
        """width, height, spp, sampler, max_depth, integrator, light_sampling, light_cells,
        mis_heuristic, accel, seed, filter, threads."""
    def set(self, **overrides: Any) -> None:
        """Changes settings (names as for :func:`render`)."""
    @property
    def counts(self) -> Dict[str, int]:
        """shapes, primitives, triangles, spheres, meshes, curves, curve_segments, patches,
        materials, textures, lights, area_light_primitives."""
    @property
    def bounds(self) -> Tuple[_Vec3, _Vec3]: ...
    @property
    def memory(self) -> Dict[str, int]:
        """Bytes of geometry, textures and the acceleration structure (accel)."""
    @property
    def accel_stats(self) -> Dict[str, Any]: ...
    def triangles(self) -> Tuple[npt.NDArray[np.float32], npt.NDArray[np.int64]]: ...
    @overload
    def render(self, *, aovs: None = None, threads: Optional[int] = None) -> npt.NDArray[np.float32]: ...
    @overload
    def render(self, *, aovs: Sequence[str], threads: Optional[int] = None) -> Dict[str, npt.NDArray[np.float32]]: ...
    def trace(
        self,
        origins: _Floats,
        directions: _Floats,
        *,
        tmin: Optional[Union[float, _Floats]] = None,
        tmax: Optional[Union[float, _Floats]] = None,
        any_hit: bool = False,
        threads: Optional[int] = None,
    ) -> Dict[str, np.ndarray]: ...
