"""Fuzzing the synthesis service over real DDS: any request (spec, cell, numbers, options)
is answered, with success or a clean error, never "internal error", and the node keeps
serving. The server runs in the namespace /fuzz, so no other server answers."""

from __future__ import annotations

import json
from collections.abc import Iterator

import pytest
from fuzzing import fuzz_settings
from hypothesis import given
from hypothesis import strategies as st

rclpy = pytest.importorskip("rclpy")

from ltl_human_motion.srv import SynthesizeMotion  # noqa: E402

from ltl_human_motion.ros.client import ClientSession  # noqa: E402
from ltl_human_motion.ros.common import SpinThread  # noqa: E402
from ltl_human_motion.ros.synthesis_node import SynthesisNode  # noqa: E402

pytestmark = [pytest.mark.ros, pytest.mark.slow]
SERVICE = "/fuzz/synthesize_motion"

SPECS = st.one_of(st.sampled_from(["S1", "S2", "grasp(O1)", "F grasp(O2)", "",
                                   "grasp(O1) & (", "G F assemble(R1) & X" * 3]),
                  st.text(max_size=60))
CELLS = st.one_of(st.sampled_from(["", "paper_cell", "no_such_cell", "{", "a: *b",
                                   "regions: {}\nstart_region: R0", "../../etc/passwd"]),
                  st.text(max_size=40))
JSON_VALUES = st.recursive(st.one_of(st.none(), st.booleans(), st.floats(), st.integers(),
                                     st.text(max_size=10)),
                           lambda inner: st.one_of(st.lists(inner, max_size=3),
                                                   st.dictionaries(st.text(max_size=8), inner,
                                                                   max_size=3)),
                           max_leaves=10)
OPTIONS = st.one_of(st.just(""), st.text(max_size=40),
                    st.dictionaries(st.sampled_from(["max_seconds", "max_nodes", "backend",
                                                     "verify", "eps", "sequence_mode", "bogus"]),
                                    JSON_VALUES, max_size=3).map(json.dumps))


@pytest.fixture(scope="module")
def fuzz_server() -> Iterator[ClientSession]:
    context = rclpy.Context()
    rclpy.init(context=context)
    memory = rclpy.parameter.Parameter("store_dir", value=":memory:")
    node = SynthesisNode(namespace="/fuzz", context=context, parameter_overrides=[memory])
    spinner = SpinThread([node], context)
    try:
        with ClientSession("fuzz_client") as session:
            yield session
    finally:
        spinner.stop()
        node.destroy_node()
        rclpy.try_shutdown(context=context)


@fuzz_settings(divisor=2)
@given(spec=SPECS, cell=CELLS, variants=st.integers(0, 2**32 - 1),
       cycles=st.integers(0, 2**32 - 1), seed=st.integers(-2**31, 2**31 - 1),
       stature=st.floats(width=32), options=OPTIONS)
def test_any_request_gets_a_clean_answer(fuzz_server: ClientSession, spec: str, cell: str,
                                         variants: int, cycles: int, seed: int,
                                         stature: float, options: str) -> None:
    request = SynthesizeMotion.Request(spec=spec, cell=cell, variants=min(variants, 3)
                                       if variants % 2 else variants,
                                       cycles=min(cycles, 2) if cycles % 2 else cycles,
                                       seed=seed, stature=stature, options_json=options)
    response = fuzz_server.call(SynthesizeMotion, SERVICE, request, timeout=120.0)
    assert response.success or response.error_message
    assert "internal error" not in response.error_message, response.error_message
