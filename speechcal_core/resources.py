"""Locate bundled resources (voice clips, defaults) in a checkout or an installed wheel."""

from __future__ import annotations

from pathlib import Path

_PACKAGE_DIR = Path(__file__).resolve().parent


def resources_dir() -> Path:
    """Return the folder holding the bundled resources.

    In a source checkout (or editable install) that is ``<repo>/resources``; in a wheel
    the same files are installed as ``speechcal_core/_resources``.
    """
    for candidate in (_PACKAGE_DIR.parent / "resources", _PACKAGE_DIR / "_resources"):
        if candidate.is_dir():
            return candidate
    raise FileNotFoundError(
        f"SpeechCal resources not found next to {_PACKAGE_DIR}; reinstall the package"
    )


def resource(*parts: str) -> Path:
    """Path of one bundled resource, e.g. ``resource("voices", "index.json")``."""
    return resources_dir().joinpath(*parts)
