"""numerics.tolerance (issue 13, "accuracy for cost"): the cheapest element count whose force
error, relative to the pull-off force, meets a tolerance for the scene.

Every run here is on the time-stepped path (``numerics.model: time_stepped`` in
`convergence_cases.Case.contact`), checked against the committed independent reference
(benchmarks/convergence_reference.json) or, for the elastic and glassy bodies, against the
closed form (``model: closed_form``, exact for an elastic body).
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import convergence_cases as cc
import numpy as np
import pytest
from scenes import one_contact

from viscoadh_ros.cli.main import main
from viscoadh_ros.core.config import SceneConfig
from viscoadh_ros.core.errors import ConfigError
from viscoadh_ros.core.history import simulate_history
from viscoadh_ros.core.presets import (
    ELEMENT_LADDER,
    UNKNOWN_RATIO,
    SceneHint,
    numerics_for_tolerance,
    relaxation_times,
    relaxed_ratio,
    resolve_numerics,
)
from viscoadh_ros.core.simulator import ContactSimulator

TABLE = json.loads(
    (Path(__file__).resolve().parents[1] / "benchmarks" / "convergence_reference.json").read_text()
)["cases"]
CASES = {case.name: case for case in cc.CASES}
SPHERE = {"shape": "sphere", "radius": 1e-3}


def _force_error(case: cc.Case, result: Any, reference: dict[str, Any]) -> float:
    err = cc.errors(case, result.force, result.contact_radius, result.energy_dissipated, reference)
    return max(err["pull_off"], err["indentation"], err["retraction"])


@pytest.mark.parametrize(
    "value",
    [-1e-3, 1.0, 2.0, float("nan"), float("inf"), "tight", True],
    ids=["negative", "one", "two", "nan", "inf", "text", "bool"],
)
def test_a_bad_tolerance_is_one_config_error_naming_the_range(value: Any) -> None:
    with pytest.raises(ConfigError, match=r"^c\.numerics\.tolerance must be .*\(0, 1\)") as raised:
        one_contact(SPHERE, numerics={"tolerance": value})
    assert "\n" not in str(raised.value)


def test_a_bad_time_scale_is_refused() -> None:
    with pytest.raises(ConfigError, match=r"^c\.numerics\.time_scale must be finite and >= 0"):
        one_contact(SPHERE, numerics={"tolerance": 1e-2, "time_scale": -1.0})


def test_tolerance_zero_keeps_the_preset_and_elements_win_over_a_tolerance() -> None:
    visco = {"kelvin": [1e5], "viscosities": [1.1e5], "work": 0.05}
    assert resolve_numerics(one_contact(SPHERE, **visco).numerics).elements == 160
    assert (
        resolve_numerics(one_contact(SPHERE, numerics={"tolerance": 0.0}, **visco).numerics).elements == 160
    )
    chosen = resolve_numerics(one_contact(SPHERE, numerics={"tolerance": 1e-2}, **visco).numerics)
    assert chosen.elements == numerics_for_tolerance(1e-2, SceneHint((0.1,), "sphere", 1.1)).elements != 160
    both = one_contact(SPHERE, numerics={"tolerance": 1e-2, "elements": 100}, **visco)
    assert resolve_numerics(both.numerics).elements == 100


HINTS = {
    "elastic": (SceneHint((), "sphere", 1.0), 0.0),
    "one Kelvin element": (SceneHint((0.1,), "sphere", 1.1), 0.0),
    "one Kelvin element, G0/G_inf = 101": (SceneHint((1e-3,), "sphere", 101.0), 0.0),
    "K = 3": (SceneHint((1e-3, 1e-2, 1e-1), "sphere", 3.0), 0.0),
    "glassy over 1 s": (SceneHint((1e8,), "cone", 11.0), 1.0),
    "nothing known": (None, 0.0),
}


@pytest.mark.parametrize("name", list(HINTS))
def test_a_tighter_tolerance_never_resolves_to_fewer_elements(name: str) -> None:
    hint, time_scale = HINTS[name]
    elements, refused = [], False
    for tolerance in np.geomspace(0.5, 1e-6, 60):
        try:
            choice = numerics_for_tolerance(float(tolerance), hint, time_scale=time_scale)
        except ConfigError as error:
            assert "numerics.tolerance" in str(error) and "tighter than" in str(error)
            refused = True
            continue
        assert not refused, f"{name}: {tolerance:.2g} met after a looser tolerance was refused"
        assert choice.predicted_error <= tolerance
        elements.append(choice.elements)
    assert elements == sorted(elements), f"{name}: {elements}"
    assert elements[0] < elements[-1] <= ELEMENT_LADDER[-1]


def test_the_regime_is_recognised_from_the_material_and_the_time_scale() -> None:
    glassy = SceneHint(relaxation_times([1e6], [1e5], [1.1e14]), "sphere", relaxed_ratio(1e6, [1e5]))
    assert glassy.relaxed_ratio == pytest.approx(11.0)
    assert glassy.relaxation_times == pytest.approx((1e8,))
    assert numerics_for_tolerance(1e-3, glassy, time_scale=1.0).regime == "glassy"
    # Unknown time scale, or memory that moves more than a tenth of the tolerance: not glassy.
    assert numerics_for_tolerance(1e-3, glassy).regime == "viscoelastic"
    assert numerics_for_tolerance(1e-3, glassy, time_scale=1e5).regime == "viscoelastic"
    cheap = numerics_for_tolerance(1e-3, glassy, time_scale=1.0).elements
    assert cheap < numerics_for_tolerance(1e-3, glassy).elements
    assert numerics_for_tolerance(1e-3, SceneHint((), "sphere", 1.0)).regime == "elastic"
    k3 = numerics_for_tolerance(1e-3, SceneHint((1e-3, 1e-2, 1e-1), "sphere", UNKNOWN_RATIO))
    assert k3.regime == "viscoelastic, K >= 2"
    assert numerics_for_tolerance(1e-3, None).elements == k3.elements
    # A larger G0/G_inf never gets fewer elements (the viscoelastic error grows with it).
    counts = [
        numerics_for_tolerance(1e-2, SceneHint((1e-3,), "sphere", r)).elements for r in (1.1, 11, 101, 1001)
    ]
    assert counts == sorted(counts) and counts[0] < counts[-1], counts


@pytest.mark.parametrize(
    "name, tolerance",
    [
        ("partly relaxed deep", 1e-2),
        ("partly relaxed deep", 3e-3),
        ("Prony K=3", 1e-2),
        ("Prony K=3", 3e-3),
        ("slow retraction", 3e-3),
        ("cone", 1e-2),
        ("power law n=1.5", 3e-3),
        ("fast retraction", 5e-3),
        ("relaxed deep", 1e-2),
    ],
)
def test_the_resolved_numerics_meet_the_tolerance_against_the_independent_reference(
    name: str, tolerance: float
) -> None:
    """The scene knows no time scale (the worst viscoelastic case of its chain); the bound
    allows the reference's own uncertainty (its distance to its finest run)."""
    case = CASES[name]
    entry = TABLE[name]
    contact = case.contact(tolerance=tolerance)
    simulator = ContactSimulator(contact)
    assert simulator.model == "time_stepped"
    times, depths = case.history()
    result = simulate_history(contact, times, depth=depths)
    error = _force_error(case, result, entry)
    floor = max(entry["uncertainty"][q] for q in ("pull_off", "indentation", "retraction"))
    assert error <= tolerance + floor, (
        f"{name} at tolerance {tolerance:g} ({simulator.numerics.elements} elements): "
        f"force error {error:.2e} of the pull-off force (reference uncertainty {floor:.0e})"
    )


def _stiff_glass_error(ratio: float, deepest: float, duration: float, tolerance: float, ref_elements: int):
    """A 1 mm sphere on one Kelvin element, G0 = 1 GPa, G0/G_inf = `ratio`, retardation time
    1 ms, w = 0.01 J/m^2, pressed from -0.5 to `deepest` relaxed d_c and pulled to -3 d_c over
    `duration` s (1001 rows), on the time-stepped path (``numerics.model: time_stepped``) with
    `tolerance`: its largest force error relative to the pull-off force (the convergence
    study's rows), the elements chosen and the reference's peak-to-pull-off ratio, against the
    same core at `ref_elements` elements with `accurate` numerics."""
    from viscoadh_ros.core import reference
    from viscoadh_ros.core.rheology import CreepElement

    g0, tau = 1e9, 1e-3
    g1 = g0 / (ratio - 1.0)

    def body(**numerics: Any) -> Any:
        return one_contact(
            SPHERE,
            glass_shear_modulus=g0,
            kelvin=[g1],
            viscosities=[tau * (g0 + g1)],
            work=0.01,
            numerics={"model": "time_stepped", **numerics},
        )

    unit = reference.figure4_scales(1e-3, 0.01, CreepElement.from_config(body().material)).depth
    depths = abs(unit) * np.concatenate([np.linspace(-0.5, deepest, 500), np.linspace(deepest, -3.0, 501)])
    times = np.linspace(0.0, duration, 1001)
    contact = body(tolerance=tolerance)
    assert ContactSimulator(contact).model == "time_stepped"
    result = simulate_history(contact, times, depth=depths)
    converged = simulate_history(body(preset="accurate", elements=ref_elements), times, depth=depths)
    entry = {
        "force": converged.force,
        "radius": converged.contact_radius,
        "dissipated": converged.energy_dissipated,
    }
    # CASES["partly relaxed"] only for cc.errors' branch rows (the same 1001-row layout).
    error = _force_error(CASES["partly relaxed"], result, entry)
    peak = converged.force.max() / -converged.force.min()
    return error, ContactSimulator(contact).numerics.elements, peak


@pytest.mark.parametrize("tolerance", [1e-2, 3e-3])
def test_a_large_glass_to_relaxed_ratio_gets_the_elements_its_tolerance_needs(tolerance: float) -> None:
    """0.10.0, an outside tester: the paper's material, G0 = 1 GPa, one Kelvin element G1 = 10 MPa
    (G0/G_inf = 101), retardation time 1 ms, w = 0.01 J/m^2, a 1 mm sphere pressed to 10 relaxed
    d_c in 5 ms and pulled to -3 d_c in 5 ms (1001 rows; a/R = 0.08, valid geometry). The
    model fitted at G0/G_inf <= 11 chose 192 (1e-2) and 384 (3e-3) elements for errors of 4.8e-2
    and 1.1e-2. Reference: 4096 elements (~1e-4 of the pull-off force from converged)."""
    error, elements, _ = _stiff_glass_error(101.0, 10.0, 0.01, tolerance, 4096)
    assert error <= tolerance, f"tolerance {tolerance:g}: {elements} elements give {error:.2e}"


def test_a_thousandfold_glass_to_relaxed_ratio_meets_its_tolerance_near_its_peak_limit() -> None:
    """A second outside tester (0.10.0): the same body with G0/G_inf = 1001, pressed over 50
    retardation times to 4.75 relaxed d_c: inside the documented range (<= 10 d_c, peak 2401 x
    the pull-off <= 4 G0/G_inf). `tolerance: 1e-2` chose 1536 elements, whose error is 1.77e-2 of
    the pull-off force: the G0/G_inf term now grows above 101 (RATIO_KNEE). Reference: 8192
    elements (3.5e-4 from 32768)."""
    error, elements, peak = _stiff_glass_error(1001.0, 4.75, 0.1, 1e-2, 8192)
    assert 2000.0 < peak <= 4.0 * 1001.0
    assert error <= 1e-2, f"{elements} elements give {error:.2e}"


@pytest.mark.parametrize("tolerance", [1e-3, 1e-4, 1e-5])
@pytest.mark.parametrize("name", ["elastic deep", "glassy deep"])
def test_elastic_and_glassy_bodies_meet_tight_tolerances_against_the_closed_form(
    name: str, tolerance: float
) -> None:
    """300 d_c deep. The glassy body (relaxation time 1e8 s on a 1 s history, time_scale 1 s)
    is compared with the elastic closed form of its glass modulus, which it equals to ~3e-6."""
    case = CASES[name]
    contact = case.contact(tolerance=tolerance, time_scale=case.duration)
    elements = ContactSimulator(contact).numerics.elements
    assert elements <= 256, "the elastic model needs few elements"
    times, depths = case.history()
    result = simulate_history(contact, times, depth=depths)
    exact_contact = one_contact(
        case.indenter, glass_shear_modulus=cc.G0, work=cc.WORK, numerics={"model": "closed_form"}
    )
    exact = simulate_history(exact_contact, times, depth=depths)
    reference = {"force": exact.force, "radius": exact.contact_radius, "dissipated": exact.energy_dissipated}
    error = _force_error(case, result, reference)
    allowance = 4e-6 if name == "glassy deep" else 0.0
    assert error <= tolerance + allowance, f"{name} at {tolerance:g} ({elements} elements): {error:.2e}"


def test_the_tolerance_goes_through_a_yaml_scene_and_the_cli(tmp_path: Path, capsys: Any) -> None:
    scene = tmp_path / "scene.yaml"
    scene.write_text(
        "/**:\n  ros__parameters:\n    contacts: [probe]\n    probe:\n"
        "      indenter: {shape: sphere, radius: 0.001}\n"
        "      material: {glass_shear_modulus: 1.0e6, kelvin_shear_moduli: [1.0e5],\n"
        "                 kelvin_viscosities: [1.1e5]}\n"
        "      adhesion: {work_of_adhesion: 0.05}\n"
        "      numerics: {model: time_stepped, tolerance: 1.0e-2}\n"
    )
    contact = SceneConfig.from_yaml(scene).contact("probe")
    assert (
        ContactSimulator(contact).numerics.elements
        == numerics_for_tolerance(1e-2, SceneHint((0.1,), "sphere", 1.1)).elements
    )
    history = tmp_path / "h.csv"
    depth = 1e-6 * np.sin(np.linspace(0.0, math.pi, 50))
    history.write_text(
        "time,depth\n"
        + "\n".join(f"{float(t)!r},{float(d)!r}" for t, d in zip(np.linspace(0, 1, 50), depth, strict=True))
        + "\n"
    )
    out = tmp_path / "out.csv"
    assert main(["simulate", str(scene), str(history), "-o", str(out), "--tolerance", "2"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("viscoadh simulate: error: probe.numerics.tolerance must be") and "(0, 1)" in err, (
        err
    )
    assert "\n" not in err and not out.exists(), "a refused tolerance writes nothing"
    assert main(["simulate", str(scene), str(history), "-o", str(out), "--tolerance", "3e-3"]) == 0
    assert out.exists()


def test_the_node_takes_the_tolerance_as_a_parameter(ros_context: Any) -> None:
    from rclpy.parameter import Parameter

    from viscoadh_ros.ros.node import ViscoadhNode

    overrides = [
        Parameter("contacts", value=["finger"]),
        Parameter("finger.indenter.shape", value="sphere"),
        Parameter("finger.indenter.radius", value=0.001),
        Parameter("finger.material.glass_shear_modulus", value=1.0e6),
        Parameter("finger.material.kelvin_shear_moduli", value=[1.0e5]),
        Parameter("finger.material.kelvin_viscosities", value=[1.1e5]),
        Parameter("finger.adhesion.work_of_adhesion", value=0.05),
        Parameter("finger.numerics.tolerance", value=3e-3),
    ]
    node = ViscoadhNode(context=ros_context, parameter_overrides=overrides)
    try:
        expected = numerics_for_tolerance(3e-3, SceneHint((0.1,), "sphere", 1.1)).elements
        assert node.contacts["finger"].simulator.numerics.elements == expected
        assert node.describe_parameter("finger.numerics.tolerance").floating_point_range
        refused = node.set_parameters([Parameter("finger.numerics.tolerance", value=1.5)])[0]
        assert not refused.successful and "numerics.tolerance" in refused.reason, refused.reason
        assert node.get_parameter("finger.numerics.tolerance").value == 3e-3
        assert node.contacts["finger"].simulator.numerics.elements == expected
    finally:
        node.destroy_node()
