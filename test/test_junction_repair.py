"""Re-blending a motion whose blend or foot locking broke a check (junction_repair)."""

from __future__ import annotations

import numpy as np
import pytest

from ltl_human_motion.planning.junction_repair import UNLOCK_HOLD, UNLOCK_RAMP, unlock_weights


def test_unlock_weights_hold_around_the_frames_and_fade_out() -> None:
    fps = 120.0
    w = unlock_weights((100, 400), 600, fps)
    assert w.shape == (600,)
    hold = round(UNLOCK_HOLD * fps)
    assert np.all(w[100 - hold:100 + hold + 1] == 1.0)
    far = round((UNLOCK_HOLD + UNLOCK_RAMP) * fps) + 1
    assert w[100 + far] == 0.0 and w[0] == 0.0 and w[-1] == 0.0
    assert np.all(np.diff(w[100 + hold:100 + far]) <= 0.0)
    assert np.abs(np.diff(w)).max() < 3.0 / (UNLOCK_RAMP * fps)
    assert not unlock_weights((), 10, fps).any()


def test_a_foot_locked_through_the_other_leg_is_unlocked_there(monkeypatch) -> None:
    """S2 for a 1.65 m worker, seed 4, with the biomechanical checks: foot locking moved
    the left shank onto the right foot in a turn (self_penetration). Fading foot
    locking out around those frames verifies it; without the repairs it is refused."""
    from ltl_human_motion.ltl.spec import PAPER_SPECS
    from ltl_human_motion.planning import pipeline
    from ltl_human_motion.planning.pipeline import SynthesisOptions, resolve_cell, synthesize
    from ltl_human_motion.planning.verify import VerificationOptions

    bio = SynthesisOptions(verification=VerificationOptions(biomechanics=True), verify=False)
    cell = resolve_cell("paper_cell")
    m = synthesize(PAPER_SPECS["S2"], cell, stature=1.65, seed=4, options=bio)[0]
    assert m.verification["passed"]
    monkeypatch.setattr(pipeline, "JUNCTION_REPAIRS", 0)
    m = synthesize(PAPER_SPECS["S2"], cell, stature=1.65, seed=4, options=bio)[0]
    assert not m.verification["self_penetration"]["passed"]


@pytest.mark.slow
def test_a_junction_still_too_fast_after_one_stretch_is_stretched_again() -> None:
    """A generated cell's carry for a 1.95 m worker: a toe at a junction of two walking
    clips moved at 5.55 m/s against its 5.46 m/s limit after the junction's windows were
    doubled once; doubled again on the next repair, the motion verifies."""
    from ltl_human_motion.planning import synthesize
    from ltl_human_motion.scenarios.generator import generate_scenarios
    from ltl_human_motion.scene.cell_yaml import cell_from_yaml
    scen = generate_scenarios(9, seed=0)[8]
    cell = cell_from_yaml(scen.yaml)
    motion = synthesize("F carry(P8, Zone20)", cell, stature=scen.stature, seed=0)[0]
    assert motion.verification["passed"] and motion.verification["joint_speed"]["passed"]
