"""`viscoadh bench --sections fit` on a tiny size: well-formed rows and report (no timing assert)."""

from __future__ import annotations

from viscoadh_ros.bench.fit_speed import fit_benchmark
from viscoadh_ros.bench.report import fit_section


def test_fit_bench_rows_and_report_section() -> None:
    result = fit_benchmark(samples=150, starts=1, kelvin_starts=0)
    case = result["cases"]["standard_solid"]
    assert case["kelvin"] == 1 and case["samples"] == 150 and len(case["fits"]) == 1
    row = case["fits"][0]
    assert row["wall_s"] > 0 and row["cpu_s"] > 0
    assert set(row["start_factors"]) == {"G0", "G1", "eta1", "work_of_adhesion"}
    assert all(1 / 3 <= f <= 3 for f in row["start_factors"].values())
    if row["status"] != "failed":
        assert 0.0 < row["model_time_share"] <= 1.0 and row["model_runs"] > 0
        assert 0 <= row["covered"] <= 4
    text = "\n".join(fit_section(result))
    assert "## Fit" in text and "standard_solid (K = 1)" in text and "| 150 |" in text
