"""Every numerics input has a range the product can serve (0.10.0's outside tester): outside it
one clear error and nothing changed, never a hang, a traceback or an out-of-memory crash; the
same through the scene loader, Python and the CLI (the node: tests/test_node_faults.py)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scenes import one_contact

from viscoadh_ros.cli.main import main
from viscoadh_ros.core import _kernels
from viscoadh_ros.core.config import ContactConfig, NumericsConfig, SceneConfig
from viscoadh_ros.core.errors import ConfigError, InputError
from viscoadh_ros.core.presets import DOMAIN_RADIUS_RANGE, ELEMENTS_MAX, MAX_SUBSTEPS, resolve_numerics
from viscoadh_ros.core.simulator import FIRST_DOMAIN_LIMIT, ContactSimulator

SPHERE = {"shape": "sphere", "radius": 5e-3}


def finger(**numerics: float) -> ContactConfig:
    """The tester's standard solid: G0 1 MPa, G1 50 kPa, eta1 1.05e5 Pa s, w 0.05 J/m^2."""
    return one_contact(SPHERE, kelvin=[5e4], viscosities=[1.05e5], work=0.05, numerics=numerics)


def scene(**numerics: float) -> dict:
    section = {
        "indenter": SPHERE,
        "material": {
            "glass_shear_modulus": 1e6,
            "kelvin_shear_moduli": [5e4],
            "kelvin_viscosities": [1.05e5],
        },
        "adhesion": {"work_of_adhesion": 0.05},
        "numerics": numerics,
    }
    return {"/**": {"ros__parameters": {"contacts": ["finger"], "finger": section}}}


def test_the_limits_are_what_the_docs_and_the_kernel_say() -> None:
    assert MAX_SUBSTEPS == round(1.0 / _kernels.JUMP_RESOLUTION), "the kernel's own finest substep"
    assert DOMAIN_RADIUS_RANGE[1] == FIRST_DOMAIN_LIMIT
    text = (Path(__file__).resolve().parents[1] / "docs" / "configuration.md").read_text()
    rows = {line.split("|")[1].strip(): line for line in text.splitlines() if line.startswith("| `")}
    assert f"4..{ELEMENTS_MAX}" in rows["`elements`"]
    assert f"[{DOMAIN_RADIUS_RANGE[0]:g}, {DOMAIN_RADIUS_RANGE[1]:g}]" in rows["`domain_radius`"]
    assert f"{MAX_SUBSTEPS}" in rows["`max_substep`"]


@pytest.mark.parametrize(
    ("numerics", "match"),
    [
        # 1e8 ran out of memory (a traceback), 2e7 ran for minutes.
        (
            {"elements": 100_000_000},
            r"^finger\.numerics\.elements must be 0 \(the preset's\) or in 4\.\.65536 ",
        ),
        ({"elements": ELEMENTS_MAX + 1}, r"elements must be .* \(got 65537\)"),
        ({"elements": 3}, r"^finger\.numerics\.elements must be 0 .* or in 4\.\."),
        # 1e300 overflowed the profile: a warning and a traceback.
        ({"domain_radius": 1e300}, r"^finger\.numerics\.domain_radius must be 0 .* or in \[1e-09, 1000\] m"),
        ({"domain_radius": 1e3 * (1 + 1e-12)}, r"domain_radius must be"),
        ({"domain_radius": 1e-12}, r"domain_radius must be"),
        ({"max_substep": -1e-3}, r"^finger\.numerics\.max_substep must be finite and >= 0"),
    ],
)
def test_numerics_outside_their_range_are_one_config_error(numerics: dict, match: str) -> None:
    with pytest.raises(ConfigError, match=match):
        SceneConfig.from_dict(scene(**numerics))


@pytest.mark.parametrize(
    "numerics",
    [
        {"elements": 4},
        {"elements": ELEMENTS_MAX},
        {"domain_radius": DOMAIN_RADIUS_RANGE[0]},
        {"domain_radius": DOMAIN_RADIUS_RANGE[1]},
        {"max_substep": 1e-300},  # accepted: a step is what it may cut too finely
    ],
)
def test_numerics_at_their_bounds_load(numerics: dict) -> None:
    contact = SceneConfig.from_dict(scene(**numerics)).contact("finger")
    for key, value in numerics.items():
        assert getattr(contact.numerics, key) == value


def test_python_callers_meet_the_same_limits() -> None:
    """A NumericsConfig made in Python (not through the loader) is checked when resolved, before
    any row is allocated."""
    with pytest.raises(ConfigError, match=r"numerics\.elements must be"):
        resolve_numerics(NumericsConfig(elements=100_000_000))
    contact = finger()
    for bad in (NumericsConfig(elements=100_000_000), NumericsConfig(domain_radius=1e300)):
        with pytest.raises(ConfigError, match=r"numerics\.(elements|domain_radius) must be"):
            ContactSimulator(
                ContactConfig(id="c", indenter=contact.indenter, material=contact.material, numerics=bad)
            )


def test_a_domain_at_the_largest_radius_steps() -> None:
    sim = ContactSimulator(finger(domain_radius=DOMAIN_RADIUS_RANGE[1]))
    for k, depth in enumerate([1e-6, 1e-5, 1.0, 100.0]):
        output = sim.step(0.01 * (k + 1), depth=depth)
        assert math.isfinite(output.force) and output.force > 0.0


def _pressed(max_substep: float) -> ContactSimulator:
    sim = ContactSimulator(finger(max_substep=max_substep))
    sim.step(0.0, depth=10e-6)
    assert sim.in_contact
    return sim


@pytest.mark.parametrize("max_substep", [1e-8, 1e-300])
def test_a_step_max_substep_would_cut_too_finely_is_refused_and_changes_nothing(max_substep: float) -> None:
    """The tester's core case: a 10 ms step at max_substep 1e-8 s took 1e6 substeps, at 1e-300 s
    it never returned. Refused by depth, force and hold, naming both fixes, the state kept."""
    sim = _pressed(max_substep)
    before = sim.snapshot()
    twin = _pressed(max_substep)
    least = f"{0.01 / MAX_SUBSTEPS:.6g}"
    for step in (
        lambda: sim.step(0.01, depth=11e-6),
        lambda: sim.step(0.01, force=sim.output.force * 1.1),
        lambda: sim.advance(0.01),
        lambda: sim.step_depths(np.array([0.01, 0.0101]), np.array([11e-6, 11e-6])),
    ):
        with pytest.raises(InputError, match=r"numerics\.max_substep") as refused:
            step()
        message = str(refused.value)
        assert f"more than the {MAX_SUBSTEPS} one step may take" in message, message
        assert f"at least {least} s" in message, message
        assert sim.snapshot().time == before.time and sim.output == twin.output
    # A step of exactly MAX_SUBSTEPS substeps is served, as its twin serves it.
    if max_substep == 1e-8:
        longest = MAX_SUBSTEPS * max_substep
        assert sim.step(longest, depth=11e-6) == twin.step(longest, depth=11e-6)
        assert sim._model.substeps <= MAX_SUBSTEPS


def test_a_batch_names_the_row_whose_step_is_too_long() -> None:
    sim = _pressed(1e-7)
    with pytest.raises(InputError, match=r"^time\[2\]: a time step of 0\.1 s would take 1e\+06 substeps"):
        sim.step_depths(np.array([1e-4, 2e-4, 0.1002]), np.array([10e-6, 10e-6, 10e-6]))
    assert sim.time == 0.0


def test_a_long_step_of_an_idle_contact_costs_nothing_and_is_served() -> None:
    """Above the surface and relaxed, a step runs no substeps: a long pause between presses
    (or the node's idle heartbeat) is not refused, and a batch gives what stepping gives.
    (A faster body than the tester's: its memory relaxes out of contact in ~50 ms.)"""

    def quick() -> ContactSimulator:
        return ContactSimulator(
            one_contact(SPHERE, kelvin=[5e4], viscosities=[1e2], work=0.05, numerics={"max_substep": 1e-5})
        )

    stepped = quick()
    times = [0.0, 1e-3, 2e-3, 3e-3]
    depths = [-1e-6, 1e-6, 2e-6, -1e-3]  # the pull far away lets go
    for t, d in zip(times, depths, strict=True):
        stepped.step(t, depth=d)
    while not stepped.is_idle:  # the memory relaxes in 1 ms steps
        times.append(times[-1] + 1e-3)
        depths.append(-1e-3)
        stepped.step(times[-1], depth=-1e-3)
    assert len(times) < 200
    pause = [times[-1] + 100.0, times[-1] + 100.001, times[-1] + 100.002]
    outputs = [stepped.step(t, depth=d) for t, d in zip(pause, [-1e-3, 1e-6, 2e-6], strict=True)]
    assert outputs[-1].force > 0.0
    columns = quick().step_depths(np.array(times + pause), np.array(depths + [-1e-3, 1e-6, 2e-6]))
    assert columns["force"][-3:].tolist() == [o.force for o in outputs]
    assert columns["contact_radius"][-3:].tolist() == [o.contact_radius for o in outputs]
    # Not idle (in contact), the same pause is refused.
    with pytest.raises(InputError, match=r"would take 1e\+07 substeps"):
        stepped.step(pause[-1] + 100.0, depth=2e-6)


def _history(tmp_path: Path, **numerics: float) -> tuple[Path, Path]:
    import yaml

    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(scene(**numerics)))
    history = tmp_path / "h.csv"
    history.write_text("time,depth\n0,0\n0.1,1e-5\n0.2,-1e-5\n")
    return path, history


@pytest.mark.parametrize(
    ("numerics", "expected"),
    [
        ({"elements": 100_000_000}, "finger.numerics.elements must be 0 (the preset's) or in 4..65536"),
        ({"elements": 20_000_000}, "finger.numerics.elements must be"),
        ({"domain_radius": 1e300}, "finger.numerics.domain_radius must be 0"),
        ({"max_substep": 1e-9}, "time[1]: a time step of 0.1 s would take 1e+08 substeps"),
        ({"max_substep": 1e-300}, "set numerics.max_substep to at least 1e-05 s"),
    ],
)
def test_simulate_refuses_unservable_numerics_with_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture, numerics: dict, expected: str
) -> None:
    """The tester's `viscoadh simulate` cases: a traceback (exit 1) or no return in 60-120 s."""
    path, history = _history(tmp_path, **numerics)
    assert main(["simulate", str(path), str(history), "-o", str(tmp_path / "o.csv")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and expected in err, err
    assert "Traceback" not in err and not (tmp_path / "o.csv").exists()
