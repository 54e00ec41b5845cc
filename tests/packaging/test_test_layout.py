"""The test folders run in any combination: no module name is shared between them.

The test folders are not packages, so pytest imports every ``conftest.py`` and helper
module under its bare file name. Two helpers with one name, or a test importing
``conftest``, work when a folder runs alone and break when folders run together."""

from __future__ import annotations

import ast
from collections import defaultdict
from pathlib import Path

TESTS = Path(__file__).resolve().parents[1]


def test_no_test_module_imports_a_conftest() -> None:
    importing = []
    for path in sorted(TESTS.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            names = ([node.module] if isinstance(node, ast.ImportFrom)
                     else [a.name for a in node.names] if isinstance(node, ast.Import) else [])
            if any(name and name.split(".")[0] == "conftest" for name in names):
                importing.append(str(path.relative_to(TESTS)))
    assert importing == [], "import shared helpers from a module of their own"


def test_no_two_test_folders_share_a_module_name() -> None:
    folders: dict[str, list[str]] = defaultdict(list)
    for path in TESTS.rglob("*.py"):
        if path.name not in ("conftest.py", "__init__.py"):
            folders[path.stem].append(str(path.parent.relative_to(TESTS)))
    assert {name: where for name, where in folders.items() if len(where) > 1} == {}
