"""The study report: JSON with every item's figures, PNG plots and one HTML page.

Plots: a top view of the layouts with what differs between them
(:mod:`ltl_human_motion.study.layout`), distributions of cycle time, worst REBA, lifting
index and minimum separation (layouts overlaid), the cycle-time breakdown, and per layout a
floor "spaghetti" plot of the worker's paths and a heat map of floor occupancy. The HTML
page embeds the PNGs (base64), says which items moved and by how much, gives the reason of
every failed item and, with two layouts, shows them side by side with the differences and
their 95 % confidence intervals (Welch's t interval on the difference of means).
"""

from __future__ import annotations

import base64
import html
import json
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ltl_human_motion.atomic import atomic_write_text
from ltl_human_motion.study.layout import (
    draw_floor_plan,
    floor_axes,
    layout_changes,
    plot_layouts,
)
from ltl_human_motion.viz._common import new_figure, save_figure

__all__ = ["METRICS", "compare", "item_metrics", "summarize", "write_report"]

#: Reported figures: key -> (label, unit, better when lower?).
METRICS: dict[str, tuple[str, str]] = {
    "cycle_time": ("worker cycle time", "s"),
    "walking_share": ("walking share of the cycle", ""),
    "walking_distance": ("walking distance per cycle", "m"),
    "waiting_share": ("waiting share of the cycle", ""),
    "value_adding_share": ("value-adding share of the cycle", ""),
    "reba_max": ("worst REBA", ""),
    "reba_mean": ("mean REBA", ""),
    "rula_max": ("worst RULA", ""),
    "lifting_index": ("highest NIOSH lifting index", ""),
    "min_separation": ("minimum human-robot separation", "m"),
    "time_below_sp": ("time below S_p", "s"),
    "robot_stopped": ("robot at the slider minimum", "s"),
    "robot_cycle_time": ("robot's effective cycle time", "s"),
}
_COLORS = ("tab:blue", "tab:orange")


def item_metrics(item: dict[str, Any]) -> dict[str, float | None]:
    """The :data:`METRICS` of one item (None where not measured, e.g. without a robot)."""
    cyc, ergo, ssm = item["cycle"], item["ergonomics"]["summary"], item.get("ssm") or {}
    return {
        "cycle_time": cyc["cycle_time"],
        "walking_share": cyc["share"]["walking"],
        "walking_distance": cyc["per_cycle"]["walking_distance"],
        "waiting_share": cyc["share"]["waiting"],
        "value_adding_share": cyc["share"]["value_adding"],
        "reba_max": ergo["reba"]["max"], "reba_mean": ergo["reba"]["mean"],
        "rula_max": ergo["rula"]["max"],
        "lifting_index": ergo["max_lifting_index"] if ergo["lifts"] else None,
        "min_separation": ssm.get("min_separation"),
        "time_below_sp": ssm.get("time_below_sp"),
        "robot_stopped": ssm.get("time_min_speed"),
        "robot_cycle_time": ssm.get("effective_cycle_time"),
    }


def _values(items: Sequence[dict[str, Any]], key: str) -> np.ndarray:
    v = [item_metrics(it)[key] for it in items]
    return np.array([x for x in v if x is not None and math.isfinite(x)], dtype=np.float64)


def _t975(dof: float) -> float:
    from scipy.stats import t
    return float(t.ppf(0.975, dof))


def summarize(items: Sequence[dict[str, Any]]) -> dict[str, dict[str, float | None]]:
    """Per metric: n, mean, 95 % CI of the mean (t), sd, median, p95, min, max."""
    out = {}
    for key in METRICS:
        x = _values(items, key)
        if not len(x):
            out[key] = {"n": 0}
            continue
        sd = float(np.std(x, ddof=1)) if len(x) > 1 else 0.0
        half = _t975(len(x) - 1) * sd / math.sqrt(len(x)) if len(x) > 1 else None
        out[key] = {"n": len(x), "mean": float(np.mean(x)), "sd": sd,
                    "ci95": None if half is None else [float(np.mean(x) - half),
                                                       float(np.mean(x) + half)],
                    "median": float(np.median(x)), "p95": float(np.percentile(x, 95)),
                    "min": float(x.min()), "max": float(x.max())}
    return out


def compare(a: Sequence[dict[str, Any]], b: Sequence[dict[str, Any]]
            ) -> dict[str, dict[str, Any]]:
    """Per metric: mean of B minus mean of A with Welch's 95 % confidence interval;
    ``significant`` when the interval excludes 0."""
    out = {}
    for key in METRICS:
        x, y = _values(a, key), _values(b, key)
        if len(x) < 2 or len(y) < 2:
            out[key] = {"n_a": len(x), "n_b": len(y)}
            continue
        va, vb = np.var(x, ddof=1) / len(x), np.var(y, ddof=1) / len(y)
        diff = float(np.mean(y) - np.mean(x))
        se = math.sqrt(va + vb)
        if se == 0:
            lo = hi = diff
        else:
            dof = (va + vb) ** 2 / (va ** 2 / (len(x) - 1) + vb ** 2 / (len(y) - 1))
            half = _t975(dof) * se
            lo, hi = diff - half, diff + half
        out[key] = {"n_a": len(x), "n_b": len(y), "mean_a": float(np.mean(x)),
                    "mean_b": float(np.mean(y)), "diff": diff, "ci95": [lo, hi],
                    "significant": bool(lo > 0 or hi < 0)}
    return out


# ------------------------------------------------------------------------------ plots

def _extent(cell, paths: Sequence[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    from ltl_human_motion.viz._common import cell_bounds
    pts = np.concatenate([np.c_[p, np.zeros(len(p))] for p in paths]) if paths else None
    lo, hi = cell_bounds(cell, pts, margin=0.3)
    return lo[:2], hi[:2]


Bounds = tuple[np.ndarray, np.ndarray]


def _occupancy(paths: Sequence[np.ndarray], bounds: Bounds, cell_size: float, rate: float
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Seconds per motion in each floor square: H (nx, ny) and the bin edges x, y."""
    lo, hi = bounds
    bx = np.arange(lo[0], hi[0] + cell_size, cell_size)
    by = np.arange(lo[1], hi[1] + cell_size, cell_size)
    pts = np.concatenate(paths) if paths else np.zeros((0, 2))
    H, _, _ = np.histogram2d(pts[:, 0], pts[:, 1], bins=[bx, by])
    return H / rate / max(len(paths), 1), bx, by


def plot_spaghetti(cell, paths: Sequence[np.ndarray], path: Path, title: str,
                   robot: dict[str, Any] | None = None, bounds: Bounds | None = None
                   ) -> Path:
    """Floor plan with every worker path (pelvis) of a layout (``bounds``: the plotted
    floor (lo (2,), hi (2,)), shared by the layouts of a comparison)."""
    fig = new_figure(6.0, 5.6, dpi=110)
    ax = fig.add_subplot(111)
    draw_floor_plan(ax, cell, robot)
    alpha = float(np.clip(8.0 / max(len(paths), 1), 0.05, 0.6))
    for p in paths:
        ax.plot(p[:, 0], p[:, 1], color="tab:blue", lw=0.8, alpha=alpha, zorder=2)
    lo, hi = bounds if bounds is not None else _extent(cell, paths)
    floor_axes(ax, lo, hi, f"{title}: worker paths ({len(paths)} motions)")
    fig.tight_layout()
    save_figure(fig, path)
    return path


def plot_heatmap(cell, paths: Sequence[np.ndarray], path: Path, title: str,
                 robot: dict[str, Any] | None = None, cell_size: float = 0.1,
                 rate: float = 10.0, bounds: Bounds | None = None,
                 vmax: float | None = None) -> Path:
    """Floor occupancy: seconds per motion spent in each ``cell_size`` square (``bounds``
    and ``vmax``, the top of the colour scale, shared by the layouts of a comparison)."""
    fig = new_figure(6.6, 5.6, dpi=110)
    ax = fig.add_subplot(111)
    lo, hi = bounds if bounds is not None else _extent(cell, paths)
    H, bx, by = _occupancy(paths, (lo, hi), cell_size, rate)
    im = ax.imshow(np.where(H > 0, H, np.nan).T, origin="lower", cmap="magma_r",
                   extent=(bx[0], bx[-1], by[0], by[-1]), zorder=1, interpolation="nearest",
                   vmin=0.0, vmax=vmax)
    fig.colorbar(im, ax=ax, label=f"s per motion in {cell_size * 100:.0f} cm squares",
                 shrink=0.85)
    draw_floor_plan(ax, cell, robot)
    floor_axes(ax, lo, hi, f"{title}: floor occupancy")
    fig.tight_layout()
    save_figure(fig, path)
    return path


def plot_distributions(layouts: Sequence[dict[str, Any]], path: Path,
                       protective_distance: float | None) -> Path:
    """Histograms of cycle time, worst REBA, lifting index, minimum separation."""
    fig = new_figure(10.0, 7.0, dpi=110)
    panels = [("cycle_time", "worker cycle time [s]", None),
              ("reba_max", "worst REBA per motion (action level bands)", None),
              ("lifting_index", "highest NIOSH lifting index", 1.0),
              ("min_separation", "minimum separation to the robot [m]", protective_distance)]
    for i, (key, label, ref) in enumerate(panels):
        ax = fig.add_subplot(2, 2, i + 1)
        data = [_values(lay["items"], key) for lay in layouts]
        allv = np.concatenate(data) if data else np.zeros(0)
        if not allv.size:
            ax.text(0.5, 0.5, "not measured", ha="center", va="center",
                    transform=ax.transAxes)
        else:
            if key == "reba_max":
                bins = np.arange(0.5, 16.0, 1.0)
                for (a, b), color, name in zip(
                        ((0.5, 1.5), (1.5, 3.5), (3.5, 7.5), (7.5, 10.5), (10.5, 15.5)),
                        ("#e8f5e9", "#fffde7", "#fff3e0", "#ffebee", "#f8bbd0"),
                        ("negl.", "low", "medium", "high", "very high")):
                    ax.axvspan(a, b, color=color, zorder=0)
                    ax.text(0.5 * (a + b), 1.01, name, ha="center", va="bottom", fontsize=7,
                            transform=ax.get_xaxis_transform())
                ax.set_xticks(range(1, 16))
            else:
                lo = min(allv.min(), ref) if ref is not None else allv.min()
                hi = max(allv.max(), ref) if ref is not None else allv.max()
                span = max(hi - lo, 1e-6)
                bins = np.linspace(lo - 0.05 * span, hi + 0.05 * span, 31)
            for lay, x, color in zip(layouts, data, _COLORS):
                if x.size:
                    ax.hist(x, bins=bins, alpha=0.45, color=color,
                            label=f"{lay['label']} (mean {x.mean():.3g})")
                    ax.hist(x, bins=bins, histtype="step", color=color, lw=1.4)
            if ref is not None:
                ax.axvline(ref, color="red", ls=":", lw=1.5,
                           label="S_p" if key == "min_separation" else "LI = 1")
            ax.legend(fontsize=8)
        ax.set_xlabel(label)
        ax.set_ylabel("motions")
    fig.suptitle("Distributions over the study's motions")
    fig.tight_layout()
    save_figure(fig, path)
    return path


def plot_breakdown(layouts: Sequence[dict[str, Any]], path: Path) -> Path:
    """Mean cycle time split into walking, value-adding work and waiting, per layout."""
    fig = new_figure(6.0, 3.8, dpi=110)
    ax = fig.add_subplot(111)
    colors = {"walking": "tab:red", "value_adding": "tab:green", "waiting": "tab:grey"}
    for i, lay in enumerate(layouts):
        left = 0.0
        for cat, color in colors.items():
            vals = [it["cycle"]["per_cycle"][cat] for it in lay["items"]]
            v = float(np.mean(vals)) if vals else 0.0
            ax.barh(i, v, left=left, color=color, label=cat.replace("_", "-") if i == 0
                    else None)
            if v > 0.4:
                ax.text(left + v / 2, i, f"{v:.1f} s", ha="center", va="center",
                        color="white", fontsize=9)
            left += v
    ax.set_yticks(range(len(layouts)), [lay["label"] for lay in layouts])
    ax.set_xlabel("mean time per cycle [s]")
    ax.set_title("Cycle time and waste (walking and waiting are waste)")
    ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.28), ncol=3)
    fig.tight_layout()
    save_figure(fig, path)
    return path


# ------------------------------------------------------------------------------ HTML

def _fmt(v: Any, digits: int = 3) -> str:
    if v is None:
        return "–"
    if isinstance(v, float):
        return f"{v:.{digits}g}"
    return html.escape(str(v))


def _img(path: Path, alt: str) -> str:
    data = base64.b64encode(path.read_bytes()).decode("ascii")
    return f'<img alt="{html.escape(alt)}" src="data:image/png;base64,{data}">'


def _summary_table(summaries: dict[str, dict[str, Any]], labels: Sequence[str]) -> str:
    head = "".join(f"<th>{html.escape(lb)} mean [95% CI]</th><th>{html.escape(lb)} max</th>"
                   for lb in labels)
    rows = []
    for key, (label, unit) in METRICS.items():
        cells = []
        for lb in labels:
            s = summaries[lb][key]
            if not s.get("n"):
                cells.append("<td>–</td><td>–</td>")
                continue
            ci = s["ci95"]
            ci_txt = f" [{_fmt(ci[0])}, {_fmt(ci[1])}]" if ci else ""
            cells.append(f"<td>{_fmt(s['mean'])}{ci_txt}</td><td>{_fmt(s['max'])}</td>")
        rows.append(f"<tr><td>{html.escape(label)}{' [' + unit + ']' if unit else ''}</td>"
                    + "".join(cells) + "</tr>")
    return f"<table><tr><th>figure</th>{head}</tr>{''.join(rows)}</table>"


def _compare_table(cmp: dict[str, dict[str, Any]], a: str, b: str) -> str:
    rows = []
    for key, (label, unit) in METRICS.items():
        c = cmp[key]
        if "diff" not in c:
            continue
        mark = ' class="sig"' if c["significant"] else ""
        rows.append(f"<tr{mark}><td>{html.escape(label)}{' [' + unit + ']' if unit else ''}"
                    f"</td><td>{_fmt(c['mean_a'])}</td><td>{_fmt(c['mean_b'])}</td>"
                    f"<td>{c['diff']:+.3g}</td><td>[{c['ci95'][0]:+.3g}, {c['ci95'][1]:+.3g}]"
                    f"</td><td>{'yes' if c['significant'] else 'no'}</td></tr>")
    return (f"<table><tr><th>figure</th><th>{html.escape(a)}</th><th>{html.escape(b)}</th>"
            f"<th>{html.escape(b)} − {html.escape(a)}</th><th>95% CI</th>"
            f"<th>differs</th></tr>{''.join(rows)}</table>")


def _changes_section(changes: Sequence[Any], labels: Sequence[str], png: Path) -> str:
    if len(labels) < 2:
        return "<h2>Layout</h2>" + _img(png, "top view of the layout")
    a, b = html.escape(labels[0]), html.escape(labels[1])
    items = "".join(f"<li>{html.escape(c.describe())}</li>" for c in changes) \
        or "<li>nothing: the two cells are the same</li>"
    return (f"<h2>What differs between layouts {a} and {b}</h2><ul>{items}</ul>"
            f'<p class="note">Shifts are {b} minus {a} in the cells\' frame (x, y on the '
            "floor, z up; metres). Everything else is the same.</p>"
            + _img(png, f"top view of layouts {a} and {b}"))


def _failed_section(layouts: Sequence[dict[str, Any]]) -> str:
    rows = []
    for lay in layouts:
        for f in lay["failed"].get("items", []):
            where = f.get("task") or f.get("check") or "–"
            rows.append(f"<tr><td>{html.escape(lay['label'])}</td><td>{f['index']}</td>"
                        f"<td>{_fmt(f['stature'])}</td><td>{f['seed']}</td>"
                        f"<td>{html.escape(str(where))}</td><td class='why'>"
                        f"{html.escape(str(f.get('message') or f.get('type') or '?'))}"
                        f"</td></tr>")
    if not rows:
        return "<h2>Failed items</h2><p>None: every item was synthesized and verified.</p>"
    return ("<h2>Failed items</h2><p>Items whose motion could not be made or did not pass "
            "verification; they are left out of every figure above.</p><table><tr>"
            "<th>layout</th><th>item</th><th>stature [m]</th><th>seed</th><th>task or check"
            f"</th><th>reason</th></tr>{''.join(rows)}</table>")


_CSS = """body{font-family:sans-serif;margin:24px;max-width:1400px;color:#222}
table{border-collapse:collapse;margin:8px 0 20px}td,th{border:1px solid #bbb;padding:4px 8px;
font-size:14px;text-align:right}td:first-child,th:first-child{text-align:left}
tr.sig td{background:#fff3cd}.row{display:flex;gap:16px;flex-wrap:wrap}
.row>div{flex:1;min-width:420px}img{max-width:100%}h2{border-bottom:1px solid #ccc}
.note{color:#555;font-size:13px}td.why{text-align:left;max-width:900px}"""


def write_report(layouts: Sequence[dict[str, Any]], out: Path, meta: dict[str, Any]
                 ) -> dict[str, Any]:
    """Write ``study.json``, the PNGs and ``study.html`` into ``out``; returns the JSON."""
    from ltl_human_motion.planning.pipeline import resolve_cell
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    labels = [lay["label"] for lay in layouts]
    cells = {lay["label"]: resolve_cell(lay["cell"]) for lay in layouts}
    robot = None
    if meta.get("robot"):
        from ltl_human_motion.study.item import robot_settings
        robot = robot_settings(meta["robot"])
    sp = None
    for lay in layouts:
        for it in lay["items"]:
            if it.get("ssm"):
                sp = it["ssm"]["protective_distance"]
                break
    pngs = {"distributions": plot_distributions(layouts, out / "distributions.png", sp),
            "breakdown": plot_breakdown(layouts, out / "cycle_breakdown.png")}
    # One floor and one colour scale for all layouts, so their plots compare by eye.
    ext = [_extent(cells[lay["label"]], lay["paths"]) for lay in layouts]
    bounds = (np.min([e[0] for e in ext], axis=0), np.max([e[1] for e in ext], axis=0))
    vmax = max((float(_occupancy(lay["paths"], bounds, 0.1, 10.0)[0].max(initial=0.0))
                for lay in layouts), default=0.0) or None
    changes = layout_changes(cells[labels[0]], cells[labels[1]]) if len(layouts) > 1 else []
    pngs["layouts"] = plot_layouts([cells[lb] for lb in labels], labels, out / "layouts.png",
                                   changes, robot, bounds)
    for lay in layouts:
        lb = lay["label"]
        pngs[f"spaghetti_{lb}"] = plot_spaghetti(cells[lb], lay["paths"],
                                                 out / f"spaghetti_{lb}.png",
                                                 f"layout {lb}", robot, bounds)
        pngs[f"heatmap_{lb}"] = plot_heatmap(cells[lb], lay["paths"], out / f"heatmap_{lb}.png",
                                             f"layout {lb}", robot, bounds=bounds, vmax=vmax)
    summaries = {lay["label"]: summarize(lay["items"]) for lay in layouts}
    comparison = compare(layouts[0]["items"], layouts[1]["items"]) if len(layouts) == 2 \
        else None
    data = {"format": "ltl_human_motion.study", "version": 1, **meta,
            "layouts": {lay["label"]: {"cell": lay["cell"], "items": lay["items"],
                                       "failed": lay["failed"],
                                       "summary": summaries[lay["label"]]}
                        for lay in layouts},
            "comparison": comparison,
            "layout_changes": [c.to_dict() for c in changes],
            "report": {"html": str(out / "study.html"),
                       "plots": {k: str(v) for k, v in pngs.items()}}}
    atomic_write_text(out / "study.json", json.dumps(data, indent=1, allow_nan=False,
                                                     default=_json_default) + "\n")
    names = " vs ".join(f"layout {html.escape(lay['label'])} ({html.escape(str(lay['cell']))})"
                        for lay in layouts)
    parts = [f"<h1>Cell study: {html.escape(meta['spec'])}</h1>",
             f"<p>{names}; "
             f"{meta['variants'] * len(meta['statures'])} variants per layout, each with a "
             f"stature drawn from {', '.join(f'{s:.2f}' for s in meta['statures'])} m; robot: "
             f"{html.escape(str(meta.get('robot') or 'none'))}; seed {meta['seed']}.</p>",
             "<p>" + "; ".join(f"layout {html.escape(lay['label'])}: {len(lay['items'])} "
                               f"verified motions, {lay['failed']['count']} failed"
                               for lay in layouts) + " (reasons at the end).</p>",
             _changes_section(changes, labels, pngs["layouts"])]
    if comparison:
        parts += [f"<h2>{html.escape(labels[1])} against {html.escape(labels[0])}</h2>",
                  _compare_table(comparison, labels[0], labels[1]),
                  '<p class="note">Highlighted: the 95 % confidence interval of the '
                  "difference of means (Welch) excludes 0.</p>"]
    parts += ["<h2>Figures per layout</h2>", _summary_table(summaries, labels),
              "<h2>Distributions</h2>", _img(pngs["distributions"], "distributions"),
              "<h2>Cycle time and waste</h2>", _img(pngs["breakdown"], "cycle breakdown"),
              "<h2>Worker paths</h2>", '<div class="row">'
              + "".join(f"<div>{_img(pngs[f'spaghetti_{lb}'], f'paths {lb}')}</div>"
                        for lb in labels) + "</div>",
              "<h2>Floor occupancy</h2>", '<div class="row">'
              + "".join(f"<div>{_img(pngs[f'heatmap_{lb}'], f'heat map {lb}')}</div>"
                        for lb in labels) + "</div>",
              _failed_section(layouts),
              '<p class="note">REBA: Hignett &amp; McAtamney (2000); RULA: McAtamney &amp; '
              "Corlett (1993); lifting index: revised NIOSH equation (Waters et al. 1994), "
              "every lift from grasp to release; separation: the live SSM controller's "
              "decisions at 125 Hz in simulated time (ISO/TS 15066 S_p). Walking and "
              "waiting are waste; every other task is value-adding work.</p>"]
    page = (f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>Cell study</title>"
            f"<style>{_CSS}</style></head><body>{''.join(parts)}</body></html>\n")
    atomic_write_text(out / "study.html", page)
    return data


def _json_default(value: Any) -> Any:
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"not JSON serializable: {type(value).__name__}")
