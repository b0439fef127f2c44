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


def tracks(objects, misses, false_positives, id_switches, pairs, rmse):
    return {"tracks.objects": objects, "tracks.misses": misses, "tracks.false_positives": false_positives,
            "tracks.id_switches": id_switches, "tracks.velocity_pairs": pairs, "tracks.velocity_rmse_mps": rmse}


def test_tracks_pool_sums_the_clear_mot_counts_and_weighs_each_rmse_by_its_pairs():
    paper = {"moving.precision": 0.2}  # the paper's method has no tracks: left out, not counted as zero
    p = obj.pool_tracks([tracks(100, 10, 5, 1, 80, 0.5), paper, tracks(50, 0, 4, 0, 20, 1.0)])
    assert p["drives"] == 2 and p["objects"] == 150 and p["velocity_pairs"] == 100
    assert p["mota"] == pytest.approx(1.0 - (10 + 5 + 1 + 0 + 4 + 0) / 150)
    assert p["velocity_rmse_mps"] == pytest.approx(((0.25 * 80 + 1.0 * 20) / 100) ** 0.5)
    one = obj.pool_tracks([tracks(674, 74, 75, 5, 600, 0.919059)])
    assert one["mota"] == pytest.approx(0.771513, abs=1e-6), "one drive pools to its own MOTA"
    assert one["velocity_rmse_mps"] == pytest.approx(0.919059)


def test_tracks_pool_without_tracks_says_none():
    p = obj.pool_tracks([{"moving.precision": 0.2}, {}])
    assert p["drives"] == 0 and p["mota"] is None and p["velocity_rmse_mps"] is None
    assert obj.pool_tracks([tracks(0, 0, 0, 0, 0, None)])["velocity_rmse_mps"] is None
