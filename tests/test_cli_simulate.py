"""`viscoadh simulate`: history CSV in, result CSV out, one-line errors."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest

from viscoadh_ros.cli.main import main
from viscoadh_ros.core import reference
from viscoadh_ros.core.simulator import STEP_OUTPUT_FIELDS

SCENE = """\
/**:
  ros__parameters:
    contacts: [finger, probe]
    finger:
      indenter: {shape: sphere, radius: 0.001}
      material: {glass_shear_modulus: 1.0e6}
    probe:
      indenter: {shape: sphere, radius: 0.001}
      material: {glass_shear_modulus: 1.0e6, kelvin_shear_moduli: [1.0e5], kelvin_viscosities: [1.1e4]}
      adhesion: {work_of_adhesion: 0.05}
"""


@pytest.fixture
def scene(tmp_path: Path) -> Path:
    path = tmp_path / "scene.yaml"
    path.write_text(SCENE)
    return path


def write_history(path: Path, header: str, rows: np.ndarray) -> Path:
    path.write_text(header + "\n" + "\n".join(f"{float(a)!r},{float(b)!r}" for a, b in rows) + "\n")
    return path


def read_result(path: Path) -> dict[str, np.ndarray]:
    with open(path, newline="") as handle:
        rows = list(csv.reader(handle))
    assert tuple(rows[0]) == STEP_OUTPUT_FIELDS
    table = np.array(rows[1:], dtype=np.float64)
    return {name: table[:, i] for i, name in enumerate(rows[0])}


def test_depth_history_gives_hertz(scene: Path, tmp_path: Path, capsys) -> None:
    time = np.linspace(0.0, 1.0, 21)
    depth = np.linspace(0.0, 1e-5, 21)
    history = write_history(tmp_path / "h.csv", "time,depth", np.c_[time, depth])
    out = tmp_path / "out.csv"
    assert (
        main(
            [
                "simulate",
                str(scene),
                str(history),
                "-o",
                str(out),
                "--contact",
                "finger",
                "--model",
                "time_stepped",
            ]
        )
        == 0
    )
    assert "time_stepped" in capsys.readouterr().out
    result = read_result(out)
    assert result["time"].size == 21
    np.testing.assert_allclose(result["depth"], depth, rtol=0, atol=0, err_msg="depth column")
    np.testing.assert_allclose(
        result["force"],
        reference.hertz_force(depth, 1e-3, 4e6),
        rtol=5e-3,
        atol=1e-12,
        err_msg="Hertz through the CLI",
    )
    assert set(np.unique(result["phase"])) <= {0.0, 1.0}


def test_force_history_and_preset(scene: Path, tmp_path: Path) -> None:
    time = np.linspace(0.0, 0.1, 11)
    force = np.linspace(0.0, 1e-3, 11)
    history = write_history(tmp_path / "h.csv", "time,force", np.c_[time, force])
    out = tmp_path / "out.csv"
    assert (
        main(["simulate", str(scene), str(history), "-o", str(out), "--contact", "probe", "--preset", "fast"])
        == 0
    )
    result = read_result(out)
    in_contact = result["contact_radius"] > 0.0
    np.testing.assert_allclose(
        result["force"][in_contact], force[in_contact], rtol=1e-3, atol=1e-9, err_msg="force tracking"
    )


@pytest.mark.parametrize(
    ("content", "message"),
    [
        ("time,height\n0,1\n", "header must be"),
        ("time,depth\n0,1e-6\n0.1,abc\n", ":3: column 'depth' is not a number"),
        ("time,depth\n0,1e-6\n0.1,nan\n", ":3: column 'depth' must be finite"),
        ("time,depth\n0,1e-6\n0,2e-6\n", ":3: column 'time' must increase"),
        ("time,depth\n0,1e-6,3\n", ":2: expected 2 columns"),
        ("time,depth\n", "no samples"),
        # Python's float() reads these, a CSV number is neither (0.8.0: "1_0" was 10 m).
        ("time,depth\n0,1e-6\n0.1,1_0\n", ":3: column 'depth' is not a number ('1_0')"),
        ("time,depth\n0,1e-6\n0.1,\uff12e-5\n", ":3: column 'depth' is not a number"),
        # Beyond the largest domain (0.8.0), and a time step below the shortest.
        ("time,depth\n0,1e-6\n0.1,2e3\n", "beyond the scene's range"),
        ("time,depth\n0,1e-6\n5e-324,2e-6\n", "time[1]: a time step of 5e-324 s is shorter"),
    ],
)
def test_bad_history_is_one_line_error(
    scene: Path, tmp_path: Path, capsys, content: str, message: str
) -> None:
    history = tmp_path / "h.csv"
    history.write_text(content)
    code = main(["simulate", str(scene), str(history), "-o", str(tmp_path / "o.csv"), "--contact", "finger"])
    err = capsys.readouterr().err.strip()
    assert code == 2
    assert err.startswith("viscoadh simulate: error:") and message in err and "\n" not in err, err


def test_ambiguous_contact_and_bad_model_are_errors(scene: Path, tmp_path: Path, capsys) -> None:
    history = write_history(tmp_path / "h.csv", "time,depth", np.array([[0.0, 1e-6]]))
    assert main(["simulate", str(scene), str(history), "-o", str(tmp_path / "o.csv")]) == 2
    assert "--contact" in capsys.readouterr().err
    assert (
        main(
            [
                "simulate",
                str(scene),
                str(history),
                "-o",
                str(tmp_path / "o.csv"),
                "--contact",
                "probe",
                "--model",
                "closed_form",
            ]
        )
        == 2
    )
    assert "numerics.model" in capsys.readouterr().err


def test_a_history_with_a_byte_order_mark_is_read(scene: Path, tmp_path: Path) -> None:
    """Spreadsheets save 'CSV UTF-8' with a BOM; the header must still read 'time,depth'."""
    history = tmp_path / "excel.csv"
    history.write_text("time,depth\n0,0\n0.1,1e-6\n", encoding="utf-8-sig")
    out = tmp_path / "o.csv"
    assert main(["simulate", str(scene), str(history), "-o", str(out), "--contact", "finger"]) == 0
    assert read_result(out)["depth"].tolist() == [0.0, 1e-6]


def test_an_output_in_a_missing_folder_is_refused_before_running(scene: Path, tmp_path: Path, capsys) -> None:
    history = write_history(tmp_path / "h.csv", "time,depth", np.array([[0.0, 1e-6]]))
    out = tmp_path / "missing" / "o.csv"
    assert main(["simulate", str(scene), str(history), "-o", str(out), "--contact", "finger"]) == 2
    err = capsys.readouterr().err.strip()
    assert "does not exist" in err and "\n" not in err, err
    assert not out.parent.exists(), "no folder is created"


@pytest.mark.parametrize("target", ["scene", "history"])
def test_an_output_on_an_input_is_refused(scene: Path, tmp_path: Path, capsys, target: str) -> None:
    """`-o` naming the scene or the history replaced it with the results and exited 0 (0.8.0's
    outside tester; replay, fit and plot refused it already): refused, the input unchanged."""
    history = write_history(tmp_path / "h.csv", "time,depth", np.array([[0.0, 1e-6], [0.1, 2e-6]]))
    victim = scene if target == "scene" else history
    before = victim.read_bytes()
    code = main(["simulate", str(scene), str(history), "-o", str(victim), "--contact", "finger"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and "would overwrite the input" in err and "\n" not in err, err
    assert victim.read_bytes() == before


def test_an_adhesive_neck_beyond_any_domain_is_a_one_line_error(tmp_path: Path, capsys) -> None:
    """A power law that rises slower than the adhesive neck (exponent 0.1, coefficient 1e-30)
    passes the scene's ranges, but its neck radius search ran to 1e300 m: a traceback from the
    first row's element width (0.8.0's outside tester). Now one line, exit 2."""
    path = tmp_path / "flat.yaml"
    path.write_text(
        "/**:\n  ros__parameters:\n    contacts: [probe]\n    probe:\n"
        "      indenter: {shape: power_law, coefficient: 1.0e-30, exponent: 0.1}\n"
        "      material: {glass_shear_modulus: 1.0e6, kelvin_shear_moduli: [1.0e5],\n"
        "                 kelvin_viscosities: [1.1e4]}\n"
        "      adhesion: {work_of_adhesion: 0.05}\n"
    )
    assert "power_law" in path.read_text()
    history = write_history(tmp_path / "h.csv", "time,depth", np.array([[0.0, 1e-6]]))
    code = main(["simulate", str(path), str(history), "-o", str(tmp_path / "o.csv"), "--contact", "probe"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and "no first domain" in err and "\n" not in err, err
    assert not (tmp_path / "o.csv").exists()


@pytest.mark.parametrize(
    "argv, words",
    [
        (["simulate"], "the following arguments are required"),
        (["simulate", "a.yaml", "b.csv", "-o", "c.csv", "--preset", "turbo"], "invalid choice: 'turbo'"),
        (["nosuchverb"], "invalid choice: 'nosuchverb'"),
    ],
)
def test_a_usage_error_is_one_line(capsys, argv: list[str], words: str) -> None:
    """docs/cli.md: a usage error is one line on stderr and exit 2 (argparse printed its usage
    block first, 6-9 lines: 0.8.0's outside tester)."""
    with pytest.raises(SystemExit) as raised:
        main(argv)
    err = capsys.readouterr().err
    assert raised.value.code == 2
    assert err.count("\n") == 1 and words in err and err.startswith("viscoadh"), err


def test_a_key_beside_the_node_sections_is_named(tmp_path: Path, capsys) -> None:
    """A params file with something else beside its `/**` section was refused as "contacts is
    required", though contacts are there (0.8.0's outside tester): the stray key is named."""
    path = tmp_path / "notes.yaml"
    path.write_text(SCENE + "notes: hello\n")
    history = write_history(tmp_path / "h.csv", "time,depth", np.array([[0.0, 1e-6]]))
    code = main(["simulate", str(path), str(history), "-o", str(tmp_path / "o.csv"), "--contact", "finger"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and "notes: not a node section" in err and "\n" not in err, err


def test_another_nodes_section_is_left_to_that_node(tmp_path: Path, capsys) -> None:
    """A params file for several nodes: `simulate` takes the sections the node takes (`/**`,
    `viscoadh`), as `viscoadh node` runs the file; it merged every section and refused the other
    node's keys as unknown parameters (0.8.0's outside tester)."""
    path = tmp_path / "two.yaml"
    path.write_text(SCENE + "other_node:\n  ros__parameters:\n    foo: 1\n")
    history = write_history(tmp_path / "h.csv", "time,depth", np.array([[0.0, 1e-6], [0.1, 2e-6]]))
    out = tmp_path / "o.csv"
    code = main(["simulate", str(path), str(history), "-o", str(out), "--contact", "finger"])
    assert code == 0, capsys.readouterr().err
    alone = tmp_path / "alone.csv"
    assert (
        main(["simulate", str(scene_file(tmp_path)), str(history), "-o", str(alone), "--contact", "finger"])
        == 0
    )
    assert out.read_bytes() == alone.read_bytes()


def scene_file(tmp_path: Path) -> Path:
    path = tmp_path / "alone.yaml"
    path.write_text(SCENE)
    return path
