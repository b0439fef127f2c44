"""The tuner's pooled scores of moving objects (objective.pool_movers), on hand-made metrics with known answers."""
import pytest

from maf_learning import objective as obj


def mover(delay, v_share, s_share, cells, seen=True, is_mover=True):
    return {"mover": is_mover, "first_seen_s": 0.0 if seen else None, "delay_s": delay, "v_share": v_share,
            "s_share": s_share, "occupied_cells": cells}


def test_movers_pool_over_drives_with_never_detected_as_infinite():
    drive_a = {"movers_objects": {"objects": [mover(0.2, 0.9, 0.0, 100), mover(None, 0.0, 0.5, 100),
                                              mover(None, 0.0, 0.0, 0, seen=False), mover(0.0, 1.0, 0.0, 5, is_mover=False)]}}
    drive_b = {"movers_objects": {"objects": [mover(0.8, 0.5, 0.25, 200)]}}
    p = obj.pool_movers([drive_a, drive_b])
    assert p["seen"] == 3  # the unseen mover and the parked object are left out
    assert p["within_0_5s"] == 1 and p["within_1s"] == 2 and p["never"] == 1
    assert p["median_delay_s"] == pytest.approx(0.8)  # median of {0.2, 0.8, never}
    assert p["mean_v_share"] == pytest.approx((0.9 + 0.0 + 0.5) / 3)
    assert p["s_share"] == pytest.approx((0.0 * 100 + 0.5 * 100 + 0.25 * 200) / 400)


def test_median_is_never_when_most_movers_are_never_detected_and_empty_is_neutral():
    p = obj.pool_movers([{"movers_objects": {"objects": [mover(0.3, 1, 0, 10), mover(None, 0, 0, 10)]}}])
    assert p["median_delay_s"] is None
    empty = obj.pool_movers([{}])
    assert empty["seen"] == 0 and empty["median_delay_s"] is None and empty["s_share"] == 0.0
