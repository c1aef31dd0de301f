"""Commissioning metrics on synthetic decisions, and the RTDE wire format helpers."""

from __future__ import annotations

import json
import struct
from pathlib import Path

import pytest

from ltl_human_motion.robot import (
    ControlDecision,
    commissioning_metrics,
    write_commissioning_report,
)
from ltl_human_motion.robot.sim import rtde_protocol as rp


def decisions() -> list[ControlDecision]:
    """10 s at 10 Hz: far (full), a violation from 3.0 to 3.5 s at minimum speed, reduced,
    then a second violation at 7.0-7.2 s where the robot was still at 0.5."""
    out = []
    for i in range(100):
        t = i * 0.1
        if 3.0 <= t < 3.5:
            sep, slider, mode = 0.8, 0.01, "stop"
        elif 7.0 <= t < 7.2:
            sep, slider, mode = 0.9, 0.5, "reduced"
        elif 5.0 <= t < 6.0:
            sep, slider, mode = 1.3, 0.5, "reduced"
        else:
            sep, slider, mode = 2.0, 1.0, "full"
        out.append(ControlDecision(t, slider, True, mode, sep, sep, 1.0, True))
    return out


def test_metrics_summarise_the_run() -> None:
    m = commissioning_metrics(decisions(), cycle_times=[6.5, 7.0], baseline_cycle_time=6.2)
    assert m["steps"] == 100
    assert m["duration"] == pytest.approx(10.0)
    assert m["rate_hz"] == pytest.approx(10.0)
    assert m["min_separation"] == pytest.approx(0.8)
    assert m["min_separation_time"] == pytest.approx(3.0)
    assert m["time_reduced_speed"] == pytest.approx(0.5 + 1.0 + 0.2)
    assert m["time_min_speed"] == pytest.approx(0.5)
    assert m["time_by_mode"] == pytest.approx({"full": 8.3, "reduced": 1.2, "stop": 0.5})
    assert len(m["violations"]) == 2
    first, second = m["violations"]
    assert first["start"] == pytest.approx(3.0) and first["end"] == pytest.approx(3.5)
    assert first["slowed_to_min"] and not second["slowed_to_min"]
    assert second["max_slider"] == 0.5
    assert m["mean_cycle_time"] == pytest.approx(6.75)
    assert m["cycle_time_ratio"] == pytest.approx(6.75 / 6.2)


def test_report_files_are_written(tmp_path: Path) -> None:
    json_path, png_path = write_commissioning_report(decisions(), tmp_path / "out", "cell",
                                                     extra={"note": "synthetic"})
    data = json.loads(json_path.read_text())
    assert data["extra"] == {"note": "synthetic"} and data["cycle_time_ratio"] is None
    assert png_path.read_bytes()[:4] == b"\x89PNG"
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["cell.json", "cell.png"]


def test_metrics_reject_bad_input() -> None:
    with pytest.raises(ValueError, match="at least one"):
        commissioning_metrics([])
    with pytest.raises(ValueError, match="time order"):
        commissioning_metrics(decisions()[::-1])


def test_recipe_round_trip_and_types() -> None:
    names = ["timestamp", "actual_q", "joint_mode", "robot_mode", "output_bit_register_64"]
    types = [rp.output_type(n) for n in names]
    assert types == ["DOUBLE", "VECTOR6D", "VECTOR6INT32", "INT32", "BOOL"]
    recipe = rp.Recipe(3, names, types)
    payload = recipe.pack([1.5, (1, 2, 3, 4, 5, 6), (253,) * 6, 7, True])
    assert payload[0] == 3 and len(payload) == 1 + 8 + 48 + 24 + 4 + 1
    values = recipe.unpack(payload)
    assert values["actual_q"] == (1, 2, 3, 4, 5, 6) and values["output_bit_register_64"]
    with pytest.raises(rp.ProtocolError, match="expected"):
        recipe.unpack(payload[:-1])
    assert rp.input_type("speed_slider_mask") == "UINT32"
    assert rp.input_type("input_double_register_47") == "DOUBLE"
    for unknown in ("input_double_register_48", "output_int_register_01", "actual_qq"):
        assert rp.output_type(unknown) is None


def test_packet_reader_splits_a_stream() -> None:
    stream = (rp.encode_packet(rp.RTDE_REQUEST_PROTOCOL_VERSION, struct.pack(">H", 2))
              + rp.encode_text_message("hello", "test", 3)
              + rp.encode_packet(rp.RTDE_CONTROL_PACKAGE_START))
    reader = rp.PacketReader()
    packets = []
    for i in range(0, len(stream), 2):          # byte pairs: packets arrive in pieces
        packets.extend(reader.feed(stream[i:i + 2]))
    assert [p.kind for p in packets] == [ord("V"), ord("M"), ord("S")]
    assert packets[1].payload == b"\x05hello\x04test\x03"
    with pytest.raises(rp.ProtocolError, match="size"):
        list(rp.PacketReader().feed(b"\x00\x02V"))
    with pytest.raises(rp.ProtocolError, match="size"):
        list(rp.PacketReader(max_size=100).feed(b"\x10\x00V"))
