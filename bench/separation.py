"""Benchmark of human-robot separation and of the coexistence control loop.

0. Ours against python-fcl's broadphase, side by side on the same capsules: one human
   (17 capsules) against a UR5e (7 capsules), and the batched form of the control loop
   (10 predicted samples of the human at once). The two are timed in alternating batches
   in one process, so that the load of a shared machine affects both alike. Target: ours
   at least 2x faster than FCL's broadphase (and <= 20 us for the single query).
1. Time per separation query: one human (17 capsules) against a UR5e (7 capsules), with
   and without input validation, and the full per-step query (forward kinematics + capsules
   + separation).
2. Control-loop rate achieved against the simulated controller (own process, 127.0.0.1)
   with the REAL ur_rtde client: paced at 125 Hz, and unpaced (headroom). Target 125 Hz.
3. Reactive versus predictive SSM in the same closed loop: a worker walks towards the arm,
   stays, and leaves; minimum separation, time at reduced speed, first slow-down.

Prints a table and writes ``bench/results/separation.json``; medians over repeats.
Not a test: run ``python bench/separation.py`` (``--no-loop`` for parts 0 and 1 only).
Needs TCP 30004 and 29999 free on loopback.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from ltl_human_motion.atomic import atomic_write_text  # noqa: E402
from ltl_human_motion.kernel import segments  # noqa: E402
from ltl_human_motion.robot import (  # noqa: E402
    CoexistenceConfig,
    CoexistenceController,
    DecisionRecorder,
    SSMParameters,
    URSimHandle,
    commissioning_metrics,
    min_distance,
    robot_capsules,
    start_ur_sim_process,
    ur_rtde_factories,
)
from ltl_human_motion.robot.sim.port_lock import wait_port_free  # noqa: E402

HOST = "127.0.0.1"


def human_capsules(x: float, y: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """17 capsules of a standing worker at (x, y), arms reaching towards -x."""
    pts = {
        "pelvis": (0, 0, 0.95), "spine": (0, 0, 1.2), "neck": (0, 0, 1.45),
        "head": (0, 0, 1.65), "l_hip": (0, 0.1, 0.9), "r_hip": (0, -0.1, 0.9),
        "l_knee": (0, 0.1, 0.5), "r_knee": (0, -0.1, 0.5), "l_ankle": (0, 0.1, 0.08),
        "r_ankle": (0, -0.1, 0.08), "l_toe": (0.15, 0.1, 0.03), "r_toe": (0.15, -0.1, 0.03),
        "l_sh": (0, 0.2, 1.42), "r_sh": (0, -0.2, 1.42), "l_elb": (-0.25, 0.25, 1.25),
        "r_elb": (-0.25, -0.25, 1.25), "l_wr": (-0.5, 0.2, 1.2), "r_wr": (-0.5, -0.2, 1.2),
    }
    bones = [("pelvis", "spine", 0.15), ("spine", "neck", 0.16), ("neck", "head", 0.11),
             ("pelvis", "l_hip", 0.1), ("pelvis", "r_hip", 0.1), ("l_hip", "l_knee", 0.08),
             ("r_hip", "r_knee", 0.08), ("l_knee", "l_ankle", 0.06),
             ("r_knee", "r_ankle", 0.06), ("l_ankle", "l_toe", 0.05),
             ("r_ankle", "r_toe", 0.05), ("neck", "l_sh", 0.06), ("neck", "r_sh", 0.06),
             ("l_sh", "l_elb", 0.05), ("r_sh", "r_elb", 0.05), ("l_elb", "l_wr", 0.045),
             ("r_elb", "r_wr", 0.045)]
    off = np.array([x, y, 0.0])
    seg = np.array([[np.add(pts[a], off), np.add(pts[b], off)] for a, b, _ in bones])
    return seg, np.array([r for _, _, r in bones])


_BEST: dict[str, float] = {}


def time_call(fn, number: int, repeat: int, name: str = "") -> float:
    """Median seconds per call over ``repeat`` batches of ``number`` calls (the fastest
    batch is kept in ``_BEST[name]``: on a shared machine it shows the intrinsic cost)."""
    samples = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        for _ in range(number):
            fn()
        samples.append((time.perf_counter() - t0) / number)
    _BEST[name] = min(samples)
    return statistics.median(samples)


def bench_query(repeat: int) -> dict[str, float]:
    hs, hr = human_capsules(1.2, 0.3)
    q = np.radians([10, -100, -90, -80, 90, 0])
    rs, rr = robot_capsules(q, "ur5e")
    out = {
        "human_capsules": len(hs), "robot_capsules": len(rs),
        "min_distance_us": 1e6 * time_call(lambda: min_distance(hs, hr, rs, rr), 2000, repeat,
                                           "min_distance_us"),
        "min_distance_unvalidated_us": 1e6 * time_call(
            lambda: min_distance(hs, hr, rs, rr, validate=False), 2000, repeat,
            "min_distance_unvalidated_us"),
        "fk_capsules_us": 1e6 * time_call(lambda: robot_capsules(q, "ur5e"), 2000, repeat,
                                          "fk_capsules_us"),
    }

    def full() -> float:
        seg, rad = robot_capsules(q, "ur5e")
        return min_distance(hs, hr, seg, rad, validate=False)

    out["fk_plus_separation_us"] = 1e6 * time_call(full, 2000, repeat, "fk_plus_separation_us")
    try:   # the project's own body capsules (scene.occupancy), if that layer is present
        from ltl_human_motion.motion.skeleton import Skeleton
        from ltl_human_motion.scene.occupancy import capsules_from_positions
    except ImportError:
        return out
    bs, br = capsules_from_positions(Skeleton().rest_positions() + np.array([1.2, 0.3, 0.0]))
    out["body_capsules"] = len(bs)
    out["min_distance_body_us"] = 1e6 * time_call(lambda: min_distance(bs, br, rs, rr), 2000,
                                                  repeat, "min_distance_body_us")
    return out


HORIZONS = 10
"""Predicted samples per control cycle in the batched query (0.1 s to 1 s ahead, as the
walking worker below feeds them)."""


def _fcl_manager(seg: np.ndarray, rad: np.ndarray):
    """A python-fcl dynamic AABB tree over the capsules (K, 2, 3), (K,), set up."""
    import fcl

    from ltl_human_motion.scene.shapes import _fcl_capsule

    manager = fcl.DynamicAABBTreeCollisionManager()
    manager.registerObjects([_fcl_capsule(fcl, a, b, r) for (a, b), r in zip(seg, rad)])
    manager.setup()
    return manager


def _fcl_min_distance(human, robot) -> float:
    """FCL's broadphase distance query between two managers (m)."""
    import fcl

    data = fcl.DistanceData(request=fcl.DistanceRequest())
    human.distance(robot, data, fcl.defaultDistanceCallback)
    return float(data.result.min_distance)


def interleaved(fns: dict[str, object], number: int, repeat: int) -> dict[str, float]:
    """Median (and fastest) microseconds per call of each function, timed in alternating
    batches of ``number`` calls (``repeat`` rounds), plus the median per-round ratios to
    the first."""
    samples: dict[str, list[float]] = {k: [] for k in fns}
    for _ in range(repeat):
        for name, fn in fns.items():
            t0 = time.perf_counter()
            for _ in range(number):
                fn()
            samples[name].append((time.perf_counter() - t0) / number)
    out = {f"{k}_us": 1e6 * statistics.median(v) for k, v in samples.items()}
    out.update({f"{k}_fastest_us": 1e6 * min(v) for k, v in samples.items()})
    first = next(iter(samples))
    for k in list(samples)[1:]:
        out[f"{k}_over_{first}"] = statistics.median(
            b / a for a, b in zip(samples[first], samples[k]))
    return out


def bench_vs_fcl(repeat: int) -> dict[str, object]:
    """Ours (compiled and numpy fallback) against FCL's broadphase, same capsules."""
    hs, hr = human_capsules(1.2, 0.3)
    q = np.radians([10, -100, -90, -80, 90, 0])
    rs, rr = robot_capsules(q, "ur5e")
    human, robot = _fcl_manager(hs, hr), _fcl_manager(rs, rr)
    ours, theirs = min_distance(hs, hr, rs, rr), _fcl_min_distance(human, robot)
    single = interleaved({
        "ours": lambda: min_distance(hs, hr, rs, rr),
        "fcl_broadphase": lambda: _fcl_min_distance(human, robot),
        "ours_numpy": lambda: segments._numpy_signed_distances(hs, hr, rs, rr).min(),
    }, 1000, repeat)
    # Batched: HORIZONS predicted samples of the walking human, one minimum per sample.
    samples = [human_capsules(1.2 - 0.1 * h, 0.3) for h in range(HORIZONS)]
    ps = np.concatenate([s for s, _ in samples])
    pr = np.concatenate([r for _, r in samples])
    starts = np.arange(HORIZONS) * len(hs)
    managers = [_fcl_manager(s, r) for s, r in samples]
    batched_ours = segments.group_min_signed_distances(ps, pr, rs, rr, starts)
    batched_fcl = np.array([_fcl_min_distance(m, robot) for m in managers])
    batched = interleaved({
        "ours": lambda: segments.group_min_signed_distances(ps, pr, rs, rr, starts),
        "fcl_broadphase": lambda: [_fcl_min_distance(m, robot) for m in managers],
        "ours_numpy": lambda: np.minimum.reduceat(
            segments._numpy_signed_distances(ps, pr, rs, rr, starts).min(axis=1), starts),
    }, 200, repeat)
    return {
        "compiled": segments.compiled(),
        "single": {"human_capsules": len(hs), "robot_capsules": len(rs),
                   "ours_m": ours, "fcl_m": theirs, **single},
        "batched": {"samples": HORIZONS, "rows": len(ps), "robot_capsules": len(rs),
                    "max_abs_difference_m": float(np.abs(batched_ours - batched_fcl).max()),
                    **batched},
    }


def walking_worker(ctl: CoexistenceController, predictive: bool):
    """Occupancy feeder: from 4 m to 0.9 m at 1.2 m/s, 1 s still, back; 1 s prediction."""
    def x_at(t: float) -> float:
        approach = (4.0 - 0.9) / 1.2
        if t < approach:
            return 4.0 - 1.2 * t
        if t < approach + 1.0:
            return 0.9
        return min(4.0, 0.9 + 1.2 * (t - approach - 1.0))

    def feed(t: float) -> None:
        seg, rad = human_capsules(x_at(t))
        pred = None
        if predictive:
            pred = []
            for h in np.arange(0.1, 1.01, 0.1):
                pseg, prad = human_capsules(x_at(t + h))
                pred.append((float(h), pseg, prad))
        ctl.update_occupancy(seg, rad, time.monotonic(), pred)

    return feed, (4.0 - 0.9) / 1.2 * 2 + 1.0


def start_sim_when_free(attempts: int = 10) -> URSimHandle:
    """A simulated controller on 127.0.0.1, once no other one (another developer's test
    or demo) holds ports 30004 and 29999; they can take the port between the wait and the
    start, so a refused start is retried."""
    for attempt in range(attempts):
        wait_port_free(HOST, 30004, timeout=120.0)
        wait_port_free(HOST, 29999, timeout=120.0)
        try:
            return start_ur_sim_process(host=HOST)
        except OSError:
            if attempt == attempts - 1:
                raise
            time.sleep(1.0)
    raise AssertionError("unreachable")


def closed_loop(duration: float, rate: float | None, predictive: bool | None,
                params: SSMParameters) -> dict[str, object]:
    sim = start_sim_when_free()
    receive_factory, io_factory = ur_rtde_factories(HOST)
    recorder = DecisionRecorder()
    ctl = CoexistenceController(receive_factory, io_factory, "ur5e", params=params,
                                config=CoexistenceConfig(use_prediction=bool(predictive)),
                                on_decision=recorder)
    step_times: list[float] = []
    try:
        ctl.step()  # connect
        recorder.decisions.clear()
        if predictive is None:
            feed = None
            seg, rad = human_capsules(2.0)
        else:
            feed, duration = walking_worker(ctl, predictive)
        original_step = ctl.step

        def timed_step():
            t0 = time.perf_counter()
            d = original_step()
            step_times.append(time.perf_counter() - t0)
            return d

        ctl.step = timed_step  # type: ignore[method-assign]
        if rate is None:    # unpaced: as fast as the loop goes
            t0 = time.monotonic()
            steps = 0
            while time.monotonic() - t0 < duration:
                ctl.update_occupancy(seg, rad, time.monotonic())
                ctl.step()
                steps += 1
        else:
            if feed is None:
                def feed(_t: float) -> None:
                    ctl.update_occupancy(seg, rad, time.monotonic())
            steps = ctl.run(rate=rate, duration=duration, before_step=feed)
        status = sim.status()
    finally:
        ctl.close()
        sim.stop()
    t = np.array([d.time for d in recorder.decisions])
    dt = np.diff(t)
    result: dict[str, object] = {
        "duration_s": float(t[-1] - t[0]),
        "steps": steps,
        "achieved_rate_hz": float((len(t) - 1) / (t[-1] - t[0])),
        "median_period_ms": 1e3 * float(np.median(dt)),
        "p99_period_ms": 1e3 * float(np.percentile(dt, 99)),
        "median_step_us": 1e6 * statistics.median(step_times),
        "disconnected_steps": sum(d.mode == "disconnected" for d in recorder.decisions),
    }
    if predictive is not None:
        m = commissioning_metrics(recorder.decisions, status["cycle_times"],
                                  status["nominal_cycle_time"])
        first_slow = next((d.time - t[0] for d in recorder.decisions if d.slider < 1.0), None)
        result.update({
            "min_separation_m": m["min_separation"],
            "time_reduced_speed_s": m["time_reduced_speed"],
            "time_min_speed_s": m["time_min_speed"],
            "first_slowdown_s": first_slow,
            "violations": len(m["violations"]),
            "violations_not_at_min_speed": sum(not v["slowed_to_min"]
                                               for v in m["violations"]),
            "robot_cycles": len(status["cycle_times"]),
            "mean_cycle_time_s": m["mean_cycle_time"],
            "baseline_cycle_time_s": m["baseline_cycle_time"],
        })
    return result


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=15, help="timing batches (median)")
    parser.add_argument("--loop-seconds", type=float, default=5.0)
    parser.add_argument("--out", default=str(ROOT / "bench" / "results" / "separation.json"))
    parser.add_argument("--no-loop", action="store_true",
                        help="only the queries (parts 0 and 1), not the closed loops")
    args = parser.parse_args()
    params = SSMParameters()
    results: dict[str, object] = {
        "python": platform.python_version(), "numpy": np.__version__,
        "machine": platform.machine(), "cpus": os.cpu_count(), "ssm": params.terms(),
        "load_average_1min_at_start": os.getloadavg()[0],
    }
    segments.compiled()   # load the kernel before timing
    vs = results["vs_fcl"] = bench_vs_fcl(args.repeat)
    print(f"ours vs FCL broadphase, same capsules, interleaved (median of {args.repeat}; "
          f"compiled kernel: {vs['compiled']}):")
    for name, r in (("single", vs["single"]), ("batched", vs["batched"])):
        what = (f"{r['human_capsules']} x {r['robot_capsules']}" if name == "single"
                else f"{r['samples']} samples, {r['rows']} x {r['robot_capsules']}")
        print(f"  {name:8s} {what:26s} ours {r['ours_us']:7.1f} us   FCL "
              f"{r['fcl_broadphase_us']:7.1f} us   FCL/ours {r['fcl_broadphase_over_ours']:5.1f}x"
              f"   (numpy fallback {r['ours_numpy_us']:.1f} us; fastest batches: ours "
              f"{r['ours_fastest_us']:.1f}, FCL {r['fcl_broadphase_fastest_us']:.1f} us)")
    print(f"  same minimum: ours {vs['single']['ours_m']:.6f} m, FCL {vs['single']['fcl_m']:.6f} m;"
          f" batched max difference {vs['batched']['max_abs_difference_m']:.1e} m")
    results["query"] = bench_query(args.repeat)
    q = results["query"]
    q["fastest_batch_us"] = {k: 1e6 * v for k, v in _BEST.items()}
    print(f"separation query, {q['human_capsules']} x {q['robot_capsules']} capsules "
          f"(median of {args.repeat}):")
    for key in ("min_distance_us", "min_distance_unvalidated_us", "fk_capsules_us",
                "fk_plus_separation_us", "min_distance_body_us"):
        if key in q:
            print(f"  {key:32s} {q[key]:8.1f} us   (fastest batch "
                  f"{q['fastest_batch_us'][key]:.1f} us)")
    if "body_capsules" in q:
        print(f"  (min_distance_body_us: the skeleton's {q['body_capsules']} body capsules)")
    if args.no_loop:
        atomic_write_text(args.out, json.dumps(results, indent=2) + "\n")
        print(f"wrote {args.out}")
        return 0
    loops = {
        "paced_125hz": closed_loop(args.loop_seconds, 125.0, None, params),
        "unpaced": closed_loop(2.0, None, None, params),
        "reactive_walk_125hz": closed_loop(0.0, 125.0, False, params),
        "predictive_walk_125hz": closed_loop(0.0, 125.0, True, params),
    }
    results["control_loop"] = loops
    print("control loop against the simulated controller, real ur_rtde client:")
    for name, r in loops.items():
        print(f"  {name:24s} rate {r['achieved_rate_hz']:7.1f} Hz  period median "
              f"{r['median_period_ms']:.2f} ms p99 {r['p99_period_ms']:.2f} ms  step "
              f"{r['median_step_us']:.0f} us")
    print("reactive vs predictive (worker walks to 0.9 m at 1.2 m/s and back):")
    for name in ("reactive_walk_125hz", "predictive_walk_125hz"):
        r = loops[name]
        print(f"  {name:24s} min sep {r['min_separation_m']:.3f} m  first slow-down "
              f"{r['first_slowdown_s']:.2f} s  reduced {r['time_reduced_speed_s']:.2f} s  "
              f"at min {r['time_min_speed_s']:.2f} s  violations {r['violations']} "
              f"(not at min speed: {r['violations_not_at_min_speed']})")
    atomic_write_text(args.out, json.dumps(results, indent=2) + "\n")
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
