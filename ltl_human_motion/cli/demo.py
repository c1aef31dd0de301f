"""``ltl-human-motion demo``: the main job, end to end.

1. The paper's Sec. IV: S1 and S2 synthesized and verified in the paper's cell, with
   Fig. 2 (snapshots), Fig. 3 (right hand), GIF animations and Tab. II/III.
2. The ROS 2 loop over real DDS: the node set brought up in this process, a separate
   client node calls the synthesis service for S2, the skeleton is played on /tf and
   as markers, the occupancy is streamed, and everything is recorded to MCAP.
3. Robot coexistence: a simulated UR5e speaking RTDE (own process) and the coexistence
   node slowing it down while the worker assembles inside its workspace; commissioning
   metrics as JSON and PNG.
4. A reactive worker (GR(1), docs/reactive.md): the synthesis service returns a strategy,
   the simulated UR5e works in the assembly region R1 (RTDE, the coexistence node's
   ur_rtde client), the worker waits at the bench and assembles when the arm has left.
5. A cell study: S2 in layouts A and B of the paper cell (config/paper_cell.yaml and
   config/paper_cell_b.yaml, the bench moved), a few variants per stature 1.6/1.75/1.9 m,
   ergonomics, cycle time and offline SSM against the UR5e; JSON, PNGs and study.html.

Each part writes into its own folder under ``--out`` and the command prints a summary.
It exits 0 only if every part succeeded.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

from ltl_human_motion.atomic import atomic_write_text

NAME = "demo"
HELP = ("run the main job: paper reproduction, ROS 2 loop with MCAP recording, robot "
        "coexistence, a worker who reacts to the robot, and a study of two layouts of the "
        "paper cell")

PARTS = ("paper", "ros", "robot", "react", "study")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``ltl-human-motion demo``."""
    parser.add_argument("--out", type=Path, default=Path("out/demo"),
                        help="output folder (default out/demo)")
    parser.add_argument("--only", choices=PARTS, action="append",
                        help="run only this part (repeatable)")
    parser.add_argument("--seed", type=int, default=1,
                        help="random seed of the syntheses and the study (default 1)")
    parser.add_argument("--no-animation", action="store_true",
                        help="skip the GIF animations of the paper part")
    parser.add_argument("--playback-rate", type=float, default=2.0,
                        help="playback speed of the ROS part (default 2x real time)")
    parser.add_argument("--study-variants", type=int, default=10,
                        help="variants per stature and layout in the study part (default 10)")


def _say(msg: str) -> None:
    print(f"[demo {time.strftime('%H:%M:%S')}] {msg}", file=sys.stderr, flush=True)


def _paper(args: argparse.Namespace) -> dict:
    from ltl_human_motion.reproduce import reproduce_paper
    summary = reproduce_paper(args.out / "paper", seed=args.seed, cycles=2,
                              animation=not args.no_animation, progress=_say)
    print(summary["tables"]["tab3"])
    ok = all(all(v.values()) for v in summary["verification"].values())
    return {"ok": ok, "folder": str(args.out / "paper"), "files": summary["files"],
            "sequences": summary["sequences"], "verification": summary["verification"],
            "times": summary["times"]}


def _ros(args: argparse.Namespace) -> dict:
    from ltl_human_motion.ltl.spec import PAPER_SPECS
    from ltl_human_motion.ros.demo_loop import run_ros_demo
    _say("bringing up the ROS 2 nodes and calling the synthesis service for S2")
    summary = run_ros_demo(PAPER_SPECS["S2"], "paper_cell", args.out / "ros", seed=args.seed,
                           playback_rate=args.playback_rate)
    missed = summary.get("occupancy_deadlines_missed", 0)
    if missed:
        load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
        summary["warning"] = (
            f"the occupancy stream missed {missed} of its 10 ms deadlines (messages late or "
            f"skipped; worst {summary.get('occupancy_worst_late_ms', 0.0):.1f} ms late): "
            "a robot reading it would have seen stale occupancy; the stream's thread did not "
            f"get a core in time (load average {load:.1f} on {os.cpu_count()} cores)")
    return {"ok": bool(summary.get("success")), **summary}


def _robot(args: argparse.Namespace) -> dict:
    from ltl_human_motion.ros.coexistence_demo import run_coexistence_demo
    _say("starting the simulated UR5e (RTDE on 127.0.0.1) and the coexistence loop")
    summary = run_coexistence_demo(args.out / "coexistence")
    return {"ok": bool(summary.get("success", summary.get("ok", False))), **summary}


def _react(args: argparse.Namespace) -> dict:
    from ltl_human_motion.ros.react_demo import run_react_demo
    _say("reactive worker: strategy over the service, the UR5e in R1 (RTDE), the worker "
         "waits at the bench")
    summary = run_react_demo(args.out / "react")
    return {"ok": bool(summary.get("success")), **summary}


def _study(args: argparse.Namespace) -> dict:
    _say("cell study: layouts A and B of the paper cell, S2, UR5e (offline SSM)")
    from ltl_human_motion.study.runner import StudyConfig, run_study
    root = Path(__file__).resolve().parents[2] / "config"
    cfg = StudyConfig(cells=[str(root / "paper_cell.yaml"), str(root / "paper_cell_b.yaml")],
                      spec="S2", variants=args.study_variants, statures=(1.6, 1.75, 1.9),
                      robot=str(root / "ur_pick_place.yaml"), out=args.out / "study",
                      seed=args.seed)
    data = run_study(cfg, progress=False)
    layouts = data["layouts"]
    return {"ok": all(lay["items"] for lay in layouts.values()),
            "html": data["report"]["html"],
            "motions": {k: len(v["items"]) for k, v in layouts.items()},
            "failed": {k: v["failed"]["count"] for k, v in layouts.items()},
            "comparison": {k: c for k, c in (data["comparison"] or {}).items()
                           if c.get("significant")}}


def _status(res: dict) -> str:
    """``ok``, ``ok but`` (done, with a warning printed below it) or ``FAILED``."""
    if not res["ok"]:
        return "FAILED"
    return "ok but" if res.get("warning") else "ok"


def run(args: argparse.Namespace) -> int:
    """Run the selected parts; print and save a summary; 0 if all succeeded."""
    parts = args.only or list(PARTS)
    args.out.mkdir(parents=True, exist_ok=True)
    results: dict = {}
    runners = {"paper": _paper, "ros": _ros, "robot": _robot, "react": _react,
               "study": _study}
    for name in parts:
        t0 = time.perf_counter()
        try:
            results[name] = runners[name](args)
        except Exception as exc:  # one failed part must not hide the others' results
            results[name] = {"ok": False, "error": f"{type(exc).__name__}: {exc}"}
        results[name]["seconds"] = round(time.perf_counter() - t0, 2)
        _say(f"{name}: {_status(results[name])} ({results[name]['seconds']} s)")
    atomic_write_text(args.out / "summary.json", json.dumps(results, indent=2, default=str))
    print("\nSummary")
    for name, res in results.items():
        line = f"  {name:6s} {_status(res):6s} {res['seconds']:7.1f} s"
        if name == "paper" and res["ok"]:
            line += f"  -> {res['folder']} ({len(res['files'])} files)"
        elif name == "ros" and res["ok"]:
            line += (f"  -> {res.get('mcap')}; occupancy {res.get('occupancy_rate_hz', 0):.0f} Hz"
                     f" on average, {len(res.get('tf_frames', []))} TF frames")
        elif name == "robot" and res["ok"]:
            runs = res.get("runs", {})
            parts = [f"{mode}: min separation {r.get('min_separation', float('nan')):.2f} m, "
                     f"{r.get('time_reduced_speed', 0.0):.1f} s slowed"
                     for mode, r in runs.items()]
            line += f"  -> {args.out / 'coexistence'} ({'; '.join(parts)})"
        elif name == "react" and res["ok"]:
            line += (f"  -> {args.out / 'react' / 'react_demo.json'} (waited "
                     f"{res.get('waited_s', 0.0):.1f} s at the bench while the arm was in R1; "
                     f"assembly {1e3 * res.get('reaction_s', float('nan')):.0f} ms after it "
                     f"left; SSM slider down to {res.get('min_slider', float('nan')):.2f})")
        elif name == "study" and res["ok"]:
            counts = ", ".join(f"{k}: {n} motions" + (f" ({res['failed'][k]} failed: "
                                                         "the report says why)"
                                                         if res["failed"].get(k) else "")
                               for k, n in res["motions"].items())
            line += f"  -> {res['html']} ({counts}{_comparison_words(res['comparison'])})"
        elif not res["ok"]:
            line += f"  {res.get('error', '')}"
        print(line)
        if res["ok"] and res.get("warning"):
            print(f"         but: {res['warning']}")
    print(f"  summary: {args.out / 'summary.json'}")
    return 0 if all(r["ok"] for r in results.values()) else 1


def _comparison_words(comparison: dict) -> str:
    """The measures where layout B differs from A beyond chance (Welch's 95 % interval
    excludes 0), in words; nothing where none does."""
    from ltl_human_motion.study.report import METRICS
    parts = [f"{METRICS[key][0]} {c['diff']:+.3g}{' ' + METRICS[key][1] if METRICS[key][1] else ''}"
             f" (95% CI {c['ci95'][0]:+.3g} .. {c['ci95'][1]:+.3g})"
             for key, c in comparison.items()]
    return "; B - A: " + ", ".join(parts) if parts else "; A and B alike"
