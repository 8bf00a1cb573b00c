"""Docs that must not drift from the code: the version record and the CLI reference."""

from __future__ import annotations

import argparse
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from viscoadh_ros import __version__
from viscoadh_ros.cli.main import VERBS, build_parser

REPO = Path(__file__).resolve().parents[1]
SEMVER = re.compile(r"^(0|[1-9]\d*)\.(0|[1-9]\d*)\.(0|[1-9]\d*)(-[0-9A-Za-z.-]+)?$")


def test_version_is_semantic_and_agrees_everywhere():
    assert SEMVER.match(__version__), f"__version__ {__version__!r} is not semantic versioning"
    package_xml = ET.parse(REPO / "package.xml").getroot().findtext("version")
    assert package_xml == __version__, f"package.xml says {package_xml}, __init__ {__version__}"
    msgs_xml = ET.parse(REPO / "msg_defs" / "package.xml").getroot().findtext("version")
    assert msgs_xml == __version__, f"msg_defs/package.xml says {msgs_xml}, __init__ {__version__}"
    changelog = (REPO / "CHANGELOG.md").read_text()
    releases = re.findall(r"^## \[(\d[^\]]*)\] - \d{4}-\d{2}-\d{2}$", changelog, re.M)
    assert releases, "CHANGELOG.md has no release heading '## [X.Y.Z] - YYYY-MM-DD'"
    assert releases[0] == __version__, f"newest CHANGELOG release {releases[0]}, __init__ {__version__}"


def _verb_parser(verb: str) -> argparse.ArgumentParser | None:
    """The verb's own parser, or None when this installation lacks the verb's module."""
    parser, module = build_parser(verb)
    if module is None:
        return None
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return sub.choices[verb]


def _section(verb: str) -> str:
    text = (REPO / "docs" / "cli.md").read_text()
    match = re.search(rf"^## `viscoadh {verb}`\n(.*?)(?=^## |\Z)", text, re.S | re.M)
    assert match, f"docs/cli.md has no section '## `viscoadh {verb}`'"
    return match.group(1)


@pytest.mark.parametrize("verb", sorted(VERBS))
def test_every_cli_option_is_documented(verb: str):
    section = _section(verb)
    parser = _verb_parser(verb)
    if parser is None:
        return  # documented from its issue; the options are checked once the verb exists
    for action in parser._actions:
        if isinstance(action, argparse._HelpAction):
            continue
        names = action.option_strings or [action.dest.upper()]
        for name in names:
            assert re.search(rf"`{re.escape(name)}[` ]", section), (
                f"docs/cli.md, viscoadh {verb}: option {name} is not documented"
            )
