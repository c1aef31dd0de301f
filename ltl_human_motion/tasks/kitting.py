"""Kitting cells and specifications: N small parts on two tables and a kit tray R1.

Used by ``bench/task_planning.py``, the tests and ``config/kitting_cell.yaml`` (made
with :func:`kitting_cell_yaml`). Parts lie along the near edges of two tables left and
right of the start R0; the kit tray ``kit`` (a fixed object, the container of
``insert``, 2 cm deeper than the parts) fills region R1 behind the start, on a cart
that is not modelled (nothing below it: the planner releases a part in front of the
worker at 0.75 m).
"""

from __future__ import annotations

__all__ = ["FAMILIES", "kitting_cell_yaml", "kitting_spec"]

#: Spacing of parts along a table edge, m (two parts a hand width apart).
PART_SPACING = 0.3

#: Height of the two tables, m (a common work-table height; lower ones make the
#: planner's grasp reach touch the table).
TABLE_HEIGHT = 0.78

#: Thickness of a table top, m.
TABLE_TOP = 0.05

#: Parts rest on thin trays that are not modelled (as in the paper cell), m: a part
#: touching the table top would count as a collision when grasped.
TRAY_GAP = 0.01

#: Distance of the parts from the cell's centre line, m: 5 cm inside the tables' near
#: edges (at 1.05 m).
PART_X = 1.10

#: Specification families of the benchmark.
FAMILIES = ("grasp_each", "move_each", "response", "precedence")


def kitting_cell_yaml(n: int, name: str | None = None) -> str:
    """YAML text of a kitting cell with ``n`` parts ``P0..P{n-1}`` (n >= 1)."""
    if n < 1:
        raise ValueError(f"a kitting cell needs at least one part, got n={n}")
    half = (n + 1) // 2
    length = max(1.2, PART_SPACING * half + 0.3)
    lines = [
        f"name: {name or f'kitting_{n}'}",
        f"description: Kitting cell, {n} small parts on two tables, kit tray region R1",
        "frame: zup", "floor_z: 0.0",
        "workspace: {lo: [-3.5, -3.5, 0.0], hi: [3.5, 3.5, 2.5]}",
        "start_region: R0", "objects:",
    ]
    for i in range(n):
        side = -1.0 if i < half else 1.0
        k = i if i < half else i - half
        count = half if i < half else n - half
        y = (k - (count - 1) / 2.0) * PART_SPACING
        lines.append(f"  P{i}: {{position: [{side * PART_X:.3f}, {y:.3f}, "
                     f"{TABLE_HEIGHT + TRAY_GAP + 0.03:.2f}], shape: box, "
                     "size: [0.06, 0.06, 0.06], grasp_points: [[0.0, 0.0, 0.03]], "
                     "mass: 0.2}")
    lines += [
        "  kit: {position: [0.0, -1.85, 0.94], shape: box, size: [0.35, 0.25, 0.08], "
        "movable: false}",
        "regions:",
        "  R0: {lo: [-0.3, -0.3, 0.0], hi: [0.3, 0.3, 0.1]}",
        "  R1: {lo: [-0.2, -1.95, 0.85], hi: [0.2, -1.75, 1.0]}",
        "obstacles:",
        *_table("table_left", -1.3, length),
        *_table("table_right", 1.3, length),
        "shorthands:",
        "  assemble(R): leftHand(R) & rightHand(R)",
    ]
    return "\n".join(lines) + "\n"


def _table(name: str, x: float, length: float) -> list[str]:
    """YAML lines of a table (a top on four legs, so the space under the top is free)."""
    top = TABLE_HEIGHT - TABLE_TOP / 2
    lines = [f"  {name}:", "    parts:",
             f"      - {{shape: box, position: [{x:.3f}, 0.0, {top:.3f}], "
             f"size: [0.5, {length:.2f}, {TABLE_TOP:.2f}]}}"]
    leg = TABLE_HEIGHT - TABLE_TOP
    for dx in (-0.22, 0.22):
        for dy in (-(length / 2 - 0.03), length / 2 - 0.03):
            lines.append(f"      - {{shape: box, position: [{x + dx:.3f}, {dy:.3f}, "
                         f"{leg / 2:.3f}], size: [0.05, 0.05, {leg:.3f}]}}")
    return lines


def kitting_spec(family: str, n: int) -> str:
    """The specification of ``family`` (:data:`FAMILIES`) for ``n`` parts."""
    if family == "grasp_each":
        return " & ".join(f"F grasp(P{i})" for i in range(n))
    if family == "move_each":
        return " & ".join(f"F move(P{i}, R1)" for i in range(n))
    if family == "response":
        return " & ".join(f"F grasp(P{i}) & G(grasp(P{i}) -> F insert(P{i}, kit))"
                          for i in range(n))
    if family == "precedence":
        a, b = min(3, n - 1), min(7, n - 1)
        body = " & ".join(f"F move(P{i}, R1)" for i in range(n))
        return body if a == b else f"{body} & (!move(P{b}, R1) U move(P{a}, R1))"
    raise ValueError(f"family must be one of {', '.join(FAMILIES)}, got {family!r}")
