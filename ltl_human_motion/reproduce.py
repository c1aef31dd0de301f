"""Reproduction of the paper's Sec. IV: S1 and S2 in the paper's cell.

Writes, into one folder:

* ``fig3_right_hand.png``   right-hand x, y, z over time for S1 and S2 (paper Fig. 3);
* ``fig2_snapshots_S2.png`` snapshots of the worker in the cell (paper Fig. 2);
* ``S1.gif``, ``S2.gif``    animations of the whole motions (offscreen);
* ``tab2_goal_primitives.md``  the goal primitives made per task (paper Tab. II);
* ``tab3_times.md`` and ``times.json``  computation time per stage (paper Tab. III);
* ``S1.npz``/``.json``/``.csv``/``.bvh`` and the same for S2: the motions.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from pathlib import Path

from ltl_human_motion.atomic import atomic_write_text

#: The paper's Tab. III, seconds (Python 3, i7 9th gen 2.6 GHz laptop).
PAPER_TIMES = {
    "S1": {"automaton": 0.1, "sequence": 1.0, "planning": 614.2, "skeleton": 39.4,
           "total": 654.7},
    "S2": {"automaton": 0.1, "sequence": 1.1, "planning": 283.9, "skeleton": 47.9,
           "total": 333.0},
}

STAGES = (("automaton", "automaton_time", "Synthesize Büchi automaton"),
          ("sequence", "sequence_time", "Create task sequence"),
          ("planning", "planning_time", "Motion planning"),
          ("skeleton", "blending_time", "Create motion of human skeleton (blending)"),
          ("verification", "verification_time", "Verify the motion (not in the paper)"),
          ("total", "total_time", "Total computation time"))


def _tab2(results: dict) -> str:
    lines = ["| Spec | Task | Goal centre [x, y, z] in m (z up) | Goal primitive made | "
             "Frames (start → end) |", "|---|---|---|---|---|"]
    for name, synth in results.items():
        for step, seg in zip(synth.stats.goal_primitives, synth.timeline):
            target = step["target"]
            centre = "–" if target is None else "[" + ", ".join(f"{v:.2f}" for v in target) + "]"
            lines.append(f"| {name} | {seg.task} | {centre} | {step['primitive']} | "
                         f"{seg.start_frame} → {seg.end_frame} |")
    return "\n".join(lines) + "\n"


def _tab3(results: dict) -> tuple[str, dict]:
    times = {name: {key: float(getattr(s.stats, field)) for key, field, _ in STAGES}
             for name, s in results.items()}
    for name, s in results.items():
        times[name]["duration"] = float(s.motion.duration)
        times[name]["real_time_factor"] = float(s.stats.real_time_factor)
        times[name]["nodes_expanded"] = int(s.stats.nodes_expanded)
    names = list(results)
    head = "| Stage | " + " | ".join(f"{n} ours [ms] | {n} paper [s]" for n in names) + " |"
    lines = [head, "|---|" + "---|---|" * len(names)]
    for key, _, label in STAGES:
        cells = []
        for n in names:
            paper = PAPER_TIMES.get(n, {}).get(key)
            cells.append(f"{times[n][key] * 1e3:.2f} | {'–' if paper is None else paper}")
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    lines.append("| Motion duration [s] | " + " | ".join(
        f"{times[n]['duration']:.1f} | –" for n in names) + " |")
    lines.append("| Real-time factor (motion s / compute s) | " + " | ".join(
        f"{times[n]['real_time_factor']:.0f} | "
        f"{times[n]['duration'] / PAPER_TIMES[n]['total']:.3f}" if n in PAPER_TIMES else
        f"{times[n]['real_time_factor']:.0f} | –" for n in names) + " |")
    lines += ["", "Ours in milliseconds, the paper's in seconds. The Büchi automaton is built "
              "on the fly as the task-sequence search needs its states: its row is the "
              "set-up and the edges made during the search, the next row the rest of the "
              "search."]
    return "\n".join(lines) + "\n", times


def reproduce_paper(out_dir: str | Path, seed: int = 1, cycles: int = 2,
                    animation: bool = True, cell: str = "paper_cell",
                    progress: Callable[[str], None] | None = None) -> dict:
    """Run S1 and S2 in the paper's cell and write the figures and tables.

    Parameters
    ----------
    out_dir : path-like
    seed : int
    cycles : int
        Passes through each specification's accepting cycle (the paper's Fig. 3 shows
        two to three assemblies).
    animation : bool
        Also write GIF animations (the slowest part).
    cell : str
        Cell name or path.
    progress : callable, optional
        Called with a short message before each stage.

    Returns
    -------
    summary : dict
        Files written, sequences, times and verification results.
    """
    from ltl_human_motion.planning import exports
    from ltl_human_motion.planning.pipeline import get_library, resolve_cell, synthesize
    from ltl_human_motion.viz import plot_hand_trajectory, render_animation, render_snapshots

    say = progress or (lambda _msg: None)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    the_cell = resolve_cell(cell)
    say("loading the motion library (built once, then cached)")
    t0 = time.perf_counter()
    library = get_library()
    library_time = time.perf_counter() - t0
    # Untimed: what the first synthesis of a process builds once and every later one
    # reuses (the compiled kernels, the gait index, the cell's fields; about 0.5 s), so
    # that Tab. III shows the time of a synthesis, as the paper's does.
    say("warming up (compiled kernels, gait index, the cell's fields: once per process)")
    synthesize("F wait(1.0)", the_cell, library=library, seed=seed)
    results = {}
    for name in ("S1", "S2"):
        say(f"synthesizing {name}")
        results[name] = synthesize(name, the_cell, library=library, seed=seed,
                                   cycles=cycles)[0]
    files = []
    for name, synth in results.items():
        for ext, saver in (("npz", exports.save_npz), ("json", exports.save_json),
                           ("csv", exports.save_csv), ("bvh", exports.save_bvh)):
            path = out / f"{name}.{ext}"
            saver(synth, path)
            files.append(path.name)
    say("plotting the right hand (Fig. 3)")
    plot_hand_trajectory(list(results.values()), out / "fig3_right_hand.png")
    files.append("fig3_right_hand.png")
    s2 = results["S2"]
    say("rendering snapshots (Fig. 2)")
    picks = [0.0]
    for seg in s2.timeline:
        picks.append((seg.start_frame + seg.end_frame) / 2 / s2.motion.fps)
    picks = sorted(set(round(t, 2) for t in picks))[:6]
    render_snapshots(s2, the_cell, picks, out / "fig2_snapshots_S2.png")
    files.append("fig2_snapshots_S2.png")
    if animation:
        for name, synth in results.items():
            say(f"rendering the animation of {name}")
            render_animation(synth, the_cell, out / f"{name}.gif")
            files.append(f"{name}.gif")
    atomic_write_text(out / "tab2_goal_primitives.md", _tab2(results))
    tab3, times = _tab3(results)
    atomic_write_text(out / "tab3_times.md", tab3)
    summary = {
        "seed": seed, "cycles": cycles, "library_time": library_time,
        "library": library.summary() if hasattr(library, "summary") else {},
        "times": times, "paper_times": PAPER_TIMES,
        "sequences": {n: s.sequence for n, s in results.items()},
        "verification": {n: {k: v["passed"] for k, v in s.verification.items()
                             if isinstance(v, dict)} for n, s in results.items()},
        "files": [*files, "tab2_goal_primitives.md", "tab3_times.md", "times.json"],
    }
    atomic_write_text(out / "times.json", json.dumps(summary, indent=2, default=str))
    summary["tables"] = {"tab2": _tab2(results), "tab3": tab3}
    return summary
