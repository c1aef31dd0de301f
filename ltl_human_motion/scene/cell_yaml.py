"""Reading work cells from YAML: validation with named limits, every error naming the
file and the key (the format: :mod:`ltl_human_motion.scene.cell`).

Limits (issue 17): the YAML itself is read by :func:`~.yaml_limits.load_yaml_limited`
(size, nesting, alias expansion); every number is within :data:`MAX_CELL_COORDINATE`, the
workspace within :data:`MAX_WORKSPACE_EXTENT`, each section within
:data:`MAX_CELL_ENTRIES` (with advice on how to simplify); values in messages are
shortened; a file that is not UTF-8 is a :class:`~ltl_human_motion.errors.CellError`.
"""

from __future__ import annotations

import math
import os
import re
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from ltl_human_motion.errors import CellError, did_you_mean
from ltl_human_motion.scene.cell import Cell, Obstacle, Region, SceneObject
from ltl_human_motion.scene.frames import ZUP_FROM_YUP, extents_zup_from_yup, zup_from_yup
from ltl_human_motion.scene.shapes import Box, Cylinder, MeshShape, Shape, Sphere
from ltl_human_motion.vocabulary import INPUT_ARGUMENTS, TASK_ARGUMENTS, shorthand_conjuncts
from ltl_human_motion.yaml_limits import (
    TextFileError,
    YamlLimitError,
    load_yaml_limited,
    read_text_file,
)
from ltl_human_motion.yaml_limits import short_repr as _r

__all__ = [
    "MAX_CELL_COORDINATE",
    "MAX_CELL_ENTRIES",
    "MAX_WORKSPACE_EXTENT",
    "cell_by_name",
    "cell_from_yaml",
    "cell_search_paths",
    "load_cell",
    "looks_like_yaml",
    "resolve_cell",
]

_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
_SHORTHAND_KEY = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*(?:\(([^()]*)\))?\s*$")
_FRAMES = ("zup", "paper_yup")
#: Any number of a cell (metres, or a size, a scale): a production cell is tens of metres
#: across; beyond this, grids and meshes overflow (issue 17: x = 1e300).
MAX_CELL_COORDINATE = 1000.0
#: Floor extent of the workspace per axis (m): the clearance maps sample it every 5 cm,
#: so 100 m is 2000 x 2000 cells (32 MB); +-1e6 m asked for 17.8 PiB.
MAX_WORKSPACE_EXTENT = 100.0
#: Entries per section. The shipped cells have under 20 of each; 10,000 tiny obstacles
#: took minutes of clearance maps.
MAX_CELL_ENTRIES = {"objects": 200, "regions": 200, "obstacles": 500}
_SIMPLIFY = {
    "objects": "Keep the objects the tasks handle; others can be obstacles.",
    "regions": "Merge regions that the tasks treat alike.",
    "obstacles": "Simplify the cell: merge neighbouring obstacles into boxes that cover "
                 "them, and drop those smaller than about 5 cm (below the body's scale).",
}


# --------------------------------------------------------------------------- parsing

class _Parser:
    """Hand-written validation of the YAML mapping; every error names file and key."""

    def __init__(self, source: str, base_dir: Path, frame: str) -> None:
        self.source = source
        self.base_dir = base_dir
        self.frame = frame

    def error(self, key: str, message: str) -> CellError:
        return CellError(f"{self.source}: {key}: {message}" if key else f"{self.source}: {message}")

    def mapping(self, value: Any, key: str, allowed: set[str] | frozenset[str],
                required: tuple[str, ...] = ()) -> Mapping[str, Any]:
        if not isinstance(value, Mapping):
            raise self.error(key, f"expected a mapping, got {type(value).__name__}")
        for k in value:
            if not isinstance(k, str):
                raise self.error(key, f"keys must be strings, got {_r(k)}")
            if k not in allowed:
                raise self.error(f"{key}.{k}" if key else k,
                                 f"unknown key; {did_you_mean(k, allowed)}expected one of "
                                 f"{', '.join(sorted(allowed))}")
        for k in required:
            if k not in value:
                raise self.error(key, f"missing required key {_r(k)}")
        return value

    def number(self, value: Any, key: str) -> float:
        if isinstance(value, str):
            # YAML 1.1 reads "1e-3" (no dot) as a string; accept numeric strings.
            try:
                value = float(value)
            except ValueError:
                raise self.error(key, f"expected a number, got {_r(value)}") from None
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise self.error(key, f"expected a number, got {_r(value)}")
        if not math.isfinite(float(value)):
            raise self.error(key, f"expected a finite number, got {_r(value)}")
        if abs(float(value)) > MAX_CELL_COORDINATE:
            raise self.error(key, f"{float(value):g} lies beyond +-{MAX_CELL_COORDINATE:g} "
                                  "(MAX_CELL_COORDINATE, metres)")
        return float(value)

    def numbers(self, value: Any, key: str, n: int | tuple[int, ...]) -> np.ndarray:
        counts = (n,) if isinstance(n, int) else n
        if not isinstance(value, (list, tuple)):
            raise self.error(key, f"expected {self._count(counts)} numbers, got {_r(value)}")
        if len(value) not in counts:
            raise self.error(key, f"expected {self._count(counts)} numbers, got {len(value)}")
        return np.array([self.number(v, f"{key}[{i}]") for i, v in enumerate(value)])

    @staticmethod
    def _count(counts: tuple[int, ...]) -> str:
        return " or ".join(str(c) for c in counts)

    def point(self, value: Any, key: str) -> np.ndarray:
        p = self.numbers(value, key, 3)
        return zup_from_yup(p) if self.frame == "paper_yup" else p

    def bounds(self, lo_v: Any, hi_v: Any, key: str) -> tuple[np.ndarray, np.ndarray]:
        lo = self.point(lo_v, f"{key}.lo")
        hi = self.point(hi_v, f"{key}.hi")
        lo, hi = np.minimum(lo, hi), np.maximum(lo, hi)
        raw_lo, raw_hi = self.numbers(lo_v, f"{key}.lo", 3), self.numbers(hi_v, f"{key}.hi", 3)
        if np.any(raw_hi <= raw_lo):
            raise self.error(key, f"needs lo < hi on every axis, got lo={raw_lo.tolist()}, "
                                  f"hi={raw_hi.tolist()}")
        return lo, hi

    def name(self, value: Any, key: str) -> str:
        if not isinstance(value, str) or not _NAME.match(value):
            raise self.error(key, f"expected a name (letters, digits, _), got {_r(value)}")
        return value

    def color(self, spec: Mapping[str, Any], key: str) -> str | None:
        c = spec.get("color")
        if c is not None and not isinstance(c, str):
            raise self.error(f"{key}.color", f"expected a colour name or #rrggbb, got {_r(c)}")
        return c

    def load_mesh(self, value: Any, key: str, scale: float):
        if not isinstance(value, str) or not value:
            raise self.error(key, f"expected a file path, got {_r(value)}")
        path = Path(value)
        if not path.is_absolute():
            path = self.base_dir / path
        if not path.is_file():
            raise self.error(key, f"mesh file {path} is not a regular file" if path.exists()
                             else f"mesh file not found: {path}")
        import trimesh
        try:
            mesh = trimesh.load(str(path), force="mesh")
        except Exception as exc:  # trimesh raises many types for corrupt files
            raise self.error(key, f"cannot load mesh {path}: {exc}") from exc
        if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
            raise self.error(key, f"{path} holds no triangles")
        mesh = mesh.copy()
        mesh.apply_scale(scale)
        if self.frame == "paper_yup":
            tf = np.eye(4)
            tf[:3, :3] = ZUP_FROM_YUP
            mesh.apply_transform(tf)
        return mesh

    _SHAPE_KEYS = frozenset({"shape", "position", "size", "yaw", "mesh", "scale"})

    def shape(self, spec: Mapping[str, Any], key: str) -> Shape:
        kind = spec.get("shape", "mesh" if "mesh" in spec else None)
        if kind not in ("box", "cylinder", "sphere", "mesh"):
            raise self.error(f"{key}.shape",
                             f"expected box, cylinder, sphere or mesh, got {_r(kind)}")
        if kind != "mesh" and "position" not in spec:
            raise self.error(key, "missing required key 'position'")
        position = self.point(spec.get("position", [0, 0, 0]), f"{key}.position")
        yaw = self.number(spec.get("yaw", 0.0), f"{key}.yaw")
        if kind == "mesh":
            if "mesh" not in spec:
                raise self.error(key, "shape mesh needs a 'mesh' file")
            for k in ("size",):
                if k in spec:
                    raise self.error(f"{key}.{k}", "not allowed for a mesh (use 'scale')")
            scale = self.number(spec.get("scale", 1.0), f"{key}.scale")
            if scale <= 0:
                raise self.error(f"{key}.scale", f"expected a positive number, got {scale}")
            mesh = self.load_mesh(spec["mesh"], f"{key}.mesh", scale)
            if yaw:
                c, s = np.cos(yaw), np.sin(yaw)
                tf = np.eye(4)
                tf[:2, :2] = [[c, -s], [s, c]]
                mesh.apply_transform(tf)
            return MeshShape(mesh, position)
        for k in ("mesh", "scale"):
            if k in spec:
                raise self.error(f"{key}.{k}", f"only allowed with shape: mesh, not {kind}")
        if "size" not in spec:
            raise self.error(key, f"shape {kind} needs a 'size'")
        skey = f"{key}.size"
        if kind == "box":
            size = self.numbers(spec["size"], skey, 3)
            if self.frame == "paper_yup":
                size = extents_zup_from_yup(size)
            if np.any(size <= 0):
                raise self.error(skey, f"expected positive side lengths, got {size.tolist()}")
            return Box(position, size, yaw)
        if yaw:
            raise self.error(f"{key}.yaw", f"not allowed for a {kind} (it is symmetric)")
        if kind == "cylinder":
            size = self.numbers(spec["size"], skey, 2)
            if np.any(size <= 0):
                raise self.error(skey, f"expected positive [radius, height], got {size.tolist()}")
            return Cylinder(position, size[0], size[1])
        size = self.numbers(spec["size"], skey, 1)
        if size[0] <= 0:
            raise self.error(skey, f"expected a positive [radius], got {size.tolist()}")
        return Sphere(position, size[0])

    def obj(self, name: str, spec: Any) -> SceneObject:
        key = f"objects.{name}"
        spec = self.mapping(spec, key, self._SHAPE_KEYS | {"grasp_points", "movable",
                                                          "sitting_surface", "color",
                                                          "mass", "two_handed"},
                            required=("position",))
        shape = self.shape(spec, key)
        position = self.point(spec["position"], f"{key}.position")
        grasp = spec.get("grasp_points", [[0.0, 0.0, 0.0]])
        if not isinstance(grasp, list) or not grasp:
            raise self.error(f"{key}.grasp_points", f"expected a list of points, got {_r(grasp)}")
        offsets = np.array([self.point(g, f"{key}.grasp_points[{i}]")
                            for i, g in enumerate(grasp)])
        movable = spec.get("movable", True)
        if not isinstance(movable, bool):
            raise self.error(f"{key}.movable", f"expected true or false, got {_r(movable)}")
        sitting = None
        if "sitting_surface" in spec:
            skey = f"{key}.sitting_surface"
            s = self.mapping(spec["sitting_surface"], skey, {"lo", "hi"}, ("lo", "hi"))
            sitting = np.stack(self.bounds(s["lo"], s["hi"], skey))
        mass = self.number(spec.get("mass", 1.0), f"{key}.mass")
        if mass <= 0.0:
            raise self.error(f"{key}.mass", f"expected a positive mass in kg, got {_r(mass)}")
        two_handed = spec.get("two_handed", False)
        if not isinstance(two_handed, bool):
            raise self.error(f"{key}.two_handed", f"expected true or false, got {_r(two_handed)}")
        return SceneObject(name, position, shape, offsets, movable, sitting,
                           self.color(spec, key), mass, two_handed)

    def region(self, name: str, spec: Any) -> Region:
        key = f"regions.{name}"
        spec = self.mapping(spec, key, {"lo", "hi", "mesh", "scale", "position", "color"})
        if "mesh" in spec:
            for k in ("lo", "hi"):
                if k in spec:
                    raise self.error(f"{key}.{k}", "give either lo/hi or mesh, not both")
            scale = self.number(spec.get("scale", 1.0), f"{key}.scale")
            mesh = self.load_mesh(spec["mesh"], f"{key}.mesh", scale)
            position = self.point(spec.get("position", [0, 0, 0]), f"{key}.position")
            return Region(name, MeshShape(mesh, position))
        for k in ("scale", "position"):
            if k in spec:
                raise self.error(f"{key}.{k}", "only allowed for mesh regions")
        if "lo" not in spec or "hi" not in spec:
            raise self.error(key, "a region needs lo and hi (a box) or mesh")
        lo, hi = self.bounds(spec["lo"], spec["hi"], key)
        return Region(name, Box.from_bounds(lo, hi))

    def obstacle(self, name: str, spec: Any) -> Obstacle:
        key = f"obstacles.{name}"
        if isinstance(spec, Mapping) and "parts" in spec:
            spec = self.mapping(spec, key, {"parts", "color"})
            parts = spec["parts"]
            if not isinstance(parts, list) or not parts:
                raise self.error(f"{key}.parts", "expected a non-empty list of shapes")
            shapes = []
            for i, part in enumerate(parts):
                pkey = f"{key}.parts[{i}]"
                shapes.append(self.shape(self.mapping(part, pkey, self._SHAPE_KEYS), pkey))
            return Obstacle(name, tuple(shapes), self.color(spec, key))
        spec = self.mapping(spec, key, self._SHAPE_KEYS | {"color"})
        return Obstacle(name, (self.shape(spec, key),), self.color(spec, key))


_TOP_KEYS = {"name", "description", "frame", "floor_z", "workspace", "start_region",
             "final_region", "objects", "regions", "obstacles", "shorthands", "inputs"}


def _parse_cell(data: Any, source: str, base_dir: Path, default_name: str) -> Cell:
    pre = _Parser(source, base_dir, "zup")
    data = pre.mapping(data, "", _TOP_KEYS, required=("regions", "start_region"))
    frame = data.get("frame", "zup")
    if frame not in _FRAMES:
        raise pre.error("frame", f"expected zup or paper_yup, got {_r(frame)}")
    p = _Parser(source, base_dir, frame)

    name = data.get("name", default_name)
    if not isinstance(name, str) or not name:
        raise p.error("name", f"expected a non-empty string, got {_r(name)}")
    description = data.get("description", "")
    if not isinstance(description, str):
        raise p.error("description", f"expected a string, got {_r(description)}")
    floor_z = p.number(data.get("floor_z", 0.0), "floor_z")

    ws = p.mapping(data.get("workspace", {"lo": [-5, -5, 0], "hi": [5, 5, 3]}), "workspace",
                   {"lo", "hi"}, ("lo", "hi"))
    ws_lo, ws_hi = p.bounds(ws["lo"], ws["hi"], "workspace")
    if np.any(ws_hi[:2] - ws_lo[:2] > MAX_WORKSPACE_EXTENT):
        raise p.error("workspace", f"spans {(ws_hi - ws_lo)[:2].tolist()} m; at most "
                                   f"{MAX_WORKSPACE_EXTENT:g} m per floor axis are allowed "
                                   "(MAX_WORKSPACE_EXTENT): a cell, not a factory")

    def section(key: str) -> Mapping[str, Any]:
        value = data.get(key) or {}
        if not isinstance(value, Mapping):
            raise p.error(key, f"expected a mapping of name to description, got "
                               f"{type(value).__name__}")
        for k in value:
            p.name(k, f"{key}.{k}")
        return value

    for key in ("objects", "regions", "obstacles"):
        if len(section(key)) > MAX_CELL_ENTRIES[key]:
            raise p.error(key, f"{len(section(key))} entries; at most {MAX_CELL_ENTRIES[key]} "
                               f"are allowed (MAX_CELL_ENTRIES). {_SIMPLIFY[key]}")
    objects = {n: p.obj(n, s) for n, s in section("objects").items()}
    regions = {n: p.region(n, s) for n, s in section("regions").items()}
    obstacles = tuple(p.obstacle(n, s) for n, s in section("obstacles").items())
    clash = sorted(set(objects) & set(regions))
    if clash:
        raise p.error("regions", f"names used for both an object and a region: {clash}")
    for n in list(objects) + list(regions):
        if n in TASK_ARGUMENTS:
            raise p.error(f"objects.{n}" if n in objects else f"regions.{n}",
                          "a task name cannot name an object or a region")

    def region_ref(key: str, required: bool) -> Region | None:
        value = data.get(key)
        if value is None:
            if required:
                raise p.error(key, "missing")
            return None
        if not isinstance(value, str) or value not in regions:
            raise p.error(key, f"unknown region {_r(value)}; {did_you_mean(value, regions)}"
                               f"expected a region name: {', '.join(regions)}")
        return regions[value]

    start = region_ref("start_region", True)
    final = region_ref("final_region", False)
    inside = (start.lo[:2] >= ws_lo[:2] - 1e-9) & (start.hi[:2] <= ws_hi[:2] + 1e-9)
    if not np.all(inside):
        raise p.error("start_region", f"region {start.name!r} lies outside the workspace")

    shorthands: dict[str, tuple[tuple[str, ...], str]] = {}
    raw = data.get("shorthands") or {}
    if not isinstance(raw, Mapping):
        raise p.error("shorthands", "expected a mapping such as 'assemble(R): leftHand(R) & "
                                    "rightHand(R)'")
    for k, body in raw.items():
        key = f"shorthands.{k}"
        m = _SHORTHAND_KEY.match(str(k))
        if not m:
            raise p.error(key, "expected name(param, ...) as the key")
        sname = m.group(1)
        params = tuple(x.strip() for x in (m.group(2) or "").split(",") if x.strip())
        for x in params:
            if not _NAME.match(x):
                raise p.error(key, f"bad parameter name {_r(x)}")
        if len(set(params)) != len(params):
            raise p.error(key, "parameter names must differ")
        if sname in TASK_ARGUMENTS or sname in shorthands:
            raise p.error(key, f"{_r(sname)} is already a task or shorthand")
        if not isinstance(body, str) or not body.strip():
            raise p.error(key, f"expected the body as a string, got {_r(body)}")
        try:
            atoms = shorthand_conjuncts(body)
        except ValueError as exc:
            raise p.error(key, str(exc)) from None
        for task, args in atoms:
            if task not in TASK_ARGUMENTS and task not in shorthands:
                hint = did_you_mean(task, [*TASK_ARGUMENTS, *shorthands]).strip()
                raise p.error(key, f"unknown task {_r(task)} in body {_r(body)}"
                                   + (f"; {hint}" if hint else ""))
            for arg in args:
                if arg not in params and arg not in objects and arg not in regions:
                    try:
                        float(arg)
                    except ValueError:
                        raise p.error(key, f"{_r(arg)} in body {_r(body)} is neither a parameter "
                                           f"nor an object or region") from None
        shorthands[sname] = (params, body.strip())

    inputs: dict[str, str] = {}
    for k, topic in section("inputs").items():
        if k in TASK_ARGUMENTS or k in INPUT_ARGUMENTS or k in shorthands:
            raise p.error(f"inputs.{k}", "already a task, a built-in input or a shorthand")
        if k in objects or k in regions:
            raise p.error(f"inputs.{k}", "already names an object or a region")
        if not isinstance(topic, str) or not re.fullmatch(r"(/[A-Za-z_][A-Za-z0-9_]*)+", topic):
            raise p.error(f"inputs.{k}", f"expected the absolute name of a std_msgs/Bool "
                                         f"topic such as /cell/{k}, got {_r(topic)}")
        inputs[k] = topic

    return Cell(name=name, source=source, objects=objects, regions=regions,
                obstacles=obstacles, start_region=start, final_region=final,
                shorthands=shorthands, floor_z=floor_z, workspace_lo=ws_lo,
                workspace_hi=ws_hi, frame=frame, description=description, inputs=inputs)


def cell_from_yaml(text: str, source: str = "<inline>",
                   base_dir: str | os.PathLike[str] | None = None) -> Cell:
    """Parse a cell from YAML text.

    Parameters
    ----------
    text : str
    source : str
        Name used in error messages (and ``Cell.source``).
    base_dir : path, optional
        Folder that relative mesh paths are resolved against (default: the current one).

    Raises
    ------
    CellError
        Malformed YAML or cell description; the message names ``source`` and the key.
    """
    try:
        data = load_yaml_limited(text)
    except YamlLimitError as exc:
        raise CellError(f"{source}: {exc}") from None
    default_name = Path(source).stem if source != "<inline>" else "cell"
    return _parse_cell(data, source, Path(base_dir) if base_dir is not None else Path.cwd(),
                       default_name)


def load_cell(path: str | os.PathLike[str]) -> Cell:
    """Load a cell from a YAML file; mesh paths are relative to the file."""
    path = Path(path)
    try:
        text = read_text_file(path, "cell file")
    except TextFileError as exc:
        raise CellError(str(exc)) from None
    return cell_from_yaml(text, source=str(path), base_dir=path.parent)


def cell_search_paths() -> list[Path]:
    """Folders searched by :func:`cell_by_name`, in order.

    The source tree's ``config/`` (beside the package), then ``share/ltl_human_motion/
    config`` in any ancestor of the installed package (colcon install space), in
    ``sys.prefix`` and in every ``AMENT_PREFIX_PATH`` entry.
    """
    here = Path(__file__).resolve()
    paths = [here.parents[2] / "config"]
    for parent in here.parents:
        paths.append(parent / "share" / "ltl_human_motion" / "config")
    paths.append(Path(sys.prefix) / "share" / "ltl_human_motion" / "config")
    for prefix in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep):
        if prefix:
            paths.append(Path(prefix) / "share" / "ltl_human_motion" / "config")
    seen: list[Path] = []
    for p in paths:
        if p not in seen:
            seen.append(p)
    return seen


def cell_by_name(name: str) -> Cell:
    """Load the shipped cell ``config/<name>.yaml`` (e.g. ``"paper_cell"``).

    Raises
    ------
    CellError
        No such cell; the message lists the folders searched and the cells found.
    """
    if not isinstance(name, str) or not _NAME.match(name.removesuffix(".yaml")):
        raise CellError(f"cell name must be a plain name such as 'paper_cell', got {_r(name)}")
    stem = name.removesuffix(".yaml")
    found: set[str] = set()
    for folder in cell_search_paths():
        candidate = folder / f"{stem}.yaml"
        if candidate.is_file():
            return load_cell(candidate)
        if folder.is_dir():
            # Other YAML files live there too (bringup parameters, batch specs, robots).
            found.update(p.stem for p in folder.glob("*.yaml") if _is_cell_file(p))
    raise CellError(f"no cell named {stem!r}; {did_you_mean(stem, found)}known cells: "
                    f"{', '.join(sorted(found)) or '(none)'}")


def _is_cell_file(path: Path) -> bool:
    try:
        return "start_region:" in read_text_file(path, "cell file")
    except TextFileError:
        return False


def looks_like_yaml(text: str) -> bool:
    """True if ``text`` is inline YAML rather than a cell name or a path: it spans lines,
    is a flow mapping (``{...}``) or holds a ``key: value`` pair."""
    text = text.strip()
    return "\n" in text or text.startswith("{") or (
        ":" in text and not text.endswith((".yaml", ".yml")))


def resolve_cell(cell: Cell | str | os.PathLike[str]) -> Cell:
    """A :class:`Cell` from a Cell, a shipped cell's name, a path to a YAML file or YAML text.

    Raises
    ------
    CellError
        Empty or unknown input, or a malformed cell (the message names the file and key).
    """
    if isinstance(cell, Cell):
        return cell
    if isinstance(cell, os.PathLike):
        return load_cell(cell)
    if not isinstance(cell, str) or not cell.strip():
        raise CellError(f"cell must be a Cell, a cell name such as 'paper_cell', a YAML path "
                        f"or YAML text, got {_r(cell)}")
    text = cell.strip()
    if looks_like_yaml(text):
        return cell_from_yaml(text, source="<inline>")
    if text.endswith((".yaml", ".yml")) or "/" in text:
        return load_cell(text)
    return cell_by_name(text)

