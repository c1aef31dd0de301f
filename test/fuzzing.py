"""Shared settings of the fuzz tests (test_fuzz_*.py): example counts that scale with the
hypothesis profile (deterministic in CI: 100 // 4 = 25 per test; ``thorough``: 500)."""

from __future__ import annotations

from hypothesis import HealthCheck, settings

#: Fuzz tests run the profile's max_examples divided by this.
FUZZ_DIVISOR = 4


def fuzz_settings(divisor: int = 1) -> settings:
    """Settings for one fuzz test: the profile's examples // (FUZZ_DIVISOR * divisor)."""
    return settings(max_examples=max(settings().max_examples // (FUZZ_DIVISOR * divisor), 5),
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                           HealthCheck.function_scoped_fixture],
                    deadline=None)
