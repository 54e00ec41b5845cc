"""The folder the sync tests' synthetic sessions are made in (see ``sync_recordings``)."""

from __future__ import annotations

from pathlib import Path

import pytest


@pytest.fixture(scope="session")
def session_root(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Folder holding the sessions of this test run."""
    return tmp_path_factory.mktemp("sync_sessions")
