"""No data loss, no silent fallbacks: replay, fit and plot refuse an output that is one of their
inputs (however it is spelled), and `--contact C` whose topics are absent is an error naming
what the bag holds."""

from __future__ import annotations

import hashlib
import os
from collections.abc import Callable
from pathlib import Path

import pytest
from geometry_msgs.msg import WrenchStamped
from viscoadh_msgs.msg import IndentationCommand

from viscoadh_ros.cli.main import main
from viscoadh_ros.core.config import SceneConfig
from viscoadh_ros.io.mcap_log import McapRecorder

SCENE = SceneConfig.from_parameters(
    {
        "contacts": ["finger", "cone"],
        "finger.indenter.shape": "sphere",
        "finger.indenter.radius": 0.01,
        "finger.material.glass_shear_modulus": 1.0e6,
        "cone.indenter.shape": "cone",
        "cone.indenter.half_angle": 1.2,
        "cone.material.glass_shear_modulus": 1.0e6,
    }
)


def _node_log(path: Path, contact: str = "finger") -> Path:
    """A small log in the node's format: 5 depth commands and their wrenches on `contact`."""
    with McapRecorder(path, scene=SCENE.to_dict()) as rec:
        for i in range(5):
            command = IndentationCommand(mode=IndentationCommand.DEPTH, depth=1e-6 * i)
            command.header.stamp.sec = 10 + i
            wrench = WrenchStamped()
            wrench.header.stamp = command.header.stamp
            wrench.wrench.force.z = 0.01 * i
            rec.record(f"/{contact}/indentation", command, (10 + i) * 10**9)
            rec.record(f"/{contact}/wrench", wrench, (10 + i) * 10**9)
    return path


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _symlink(target: Path, name: str) -> Path:
    link = target.parent / name
    link.symlink_to(target)
    return link


def _hardlink(target: Path, name: str) -> Path:
    link = target.parent / name
    os.link(target, link)
    return link


#: name -> (verb, build the extra arguments from (bag, scene file) in cwd = the bag's folder)
CASES: dict[str, tuple[str, Callable[[Path, Path], list[str]]]] = {
    "replay -o the input": ("replay", lambda bag, _: ["-o", bag.name]),
    "replay -o ./input": ("replay", lambda bag, _: ["-o", f"./{bag.name}"]),
    "replay -o sub/../input": ("replay", lambda bag, _: ["-o", f"{bag.parent}/sub/../{bag.name}"]),
    "replay -o symlink": ("replay", lambda bag, _: ["-o", str(_symlink(bag, "link.mcap"))]),
    "replay -o hard link": ("replay", lambda bag, _: ["-o", str(_hardlink(bag, "hard.mcap"))]),
    "replay --json input": ("replay", lambda bag, _: ["-o", "out.mcap", "--json", f"./{bag.name}"]),
    "replay --json scene": (
        "replay",
        lambda bag, scene: ["--scene", str(scene), "-o", "out.mcap", "--json", scene.name],
    ),
    "fit -o symlink to bag": ("fit", lambda bag, _: ["-o", str(_symlink(bag, "fitted.yaml"))]),
    "fit -o ./scene": ("fit", lambda bag, scene: ["--scene", scene.name, "-o", f"./{scene.name}"]),
    "plot -o symlink": ("plot", lambda bag, _: ["-o", str(_symlink(bag, "figure.svg"))]),
    "plot -o hard link": ("plot", lambda bag, _: ["-o", str(_hardlink(bag, "figure.png"))]),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_output_that_is_an_input_is_refused(
    case: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture
) -> None:
    verb, extra = CASES[case]
    (tmp_path / "sub").mkdir()
    bag = _node_log(tmp_path / "run.mcap")
    scene = tmp_path / "scene.yaml"
    scene.write_text("contacts: [finger]\nfinger:\n  indenter: {shape: sphere, radius: 0.01}\n")
    before = {p: _digest(p) for p in (bag, scene)}
    monkeypatch.chdir(tmp_path)
    code = main([verb, bag.name, *extra(bag, scene)])
    err = capsys.readouterr().err
    assert code == 2, f"{case}: exit {code}, {err!r}"
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"viscoadh {verb}: error:"), err
    assert "would overwrite the input" in lines[0], lines[0]
    assert {p: _digest(p) for p in before} == before, f"{case}: an input changed"
    assert not (tmp_path / "out.mcap").exists(), "nothing written"


def test_output_inside_an_input_folder_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    folder = tmp_path / "bag"
    folder.mkdir()
    _node_log(folder / "bag_0.mcap")
    assert main(["replay", str(folder), "-o", str(folder / "replayed.mcap")]) == 2
    assert "would overwrite the input" in capsys.readouterr().err
    assert sorted(p.name for p in folder.iterdir()) == ["bag_0.mcap"]


def test_replay_to_a_new_path_still_works(tmp_path: Path) -> None:
    bag = _node_log(tmp_path / "run.mcap")
    assert main(["replay", str(bag), "-o", str(tmp_path / "out.mcap")]) == 0


@pytest.mark.parametrize("verb", ["replay", "fit"])
def test_contact_whose_topics_are_absent_is_an_error(
    verb: str, tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    """The scene has finger and cone; the log has only finger's topics: `--contact cone` once
    replayed finger's commands as cone's."""
    bag = _node_log(tmp_path / "run.mcap", contact="finger")
    out = tmp_path / ("out.mcap" if verb == "replay" else "out.yaml")
    code = main([verb, str(bag), "--contact", "cone", "-o", str(out)])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1, err
    assert "cone/indentation" in err and "/finger/indentation" in err, err
    assert not out.exists()


@pytest.mark.parametrize(
    "argv",
    [
        pytest.param(["replay", "{bag}", "-o", "{tmp}/missing/out.mcap"], id="replay-output"),
        pytest.param(
            ["replay", "{bag}", "-o", "{tmp}/out.mcap", "--json", "{tmp}/missing/s.json"], id="replay-json"
        ),
        pytest.param(
            ["replay", "{bag}", "{bag}", "-o", "{tmp}/missing/deeper/out"], id="replay-batch-folder"
        ),
        pytest.param(["fit", "{bag}", "-o", "{tmp}/missing/fit.yaml"], id="fit-output"),
    ],
)
def test_an_output_in_a_missing_folder_is_refused_before_any_work(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], argv: list[str]
) -> None:
    """The file rule of every verb (docs/cli.md): one line, exit 2, nothing written, no folder
    created (replay crashed with a traceback after the whole run, leaving OUT written but not
    its --json; fit created the folder)."""
    bag = _node_log(tmp_path / "log.mcap")
    before = sorted(p.relative_to(tmp_path) for p in tmp_path.rglob("*"))
    code = main([a.format(bag=bag, tmp=tmp_path) for a in argv])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2, err
    assert len(err) == 1 and "does not exist" in err[0], err
    assert sorted(p.relative_to(tmp_path) for p in tmp_path.rglob("*")) == before, "nothing written"
