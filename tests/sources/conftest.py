"""Fixtures: small bags written for real under tmp_path."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path

import pytest
from source_data import T0, Cam, regular, write_bag


@pytest.fixture
def make_bag(tmp_path: Path) -> Callable[..., Path]:
    """Factory: ``make_bag(fmt, cams, name=..., imu=...)`` writes a bag under tmp_path."""
    counter = iter(range(1000))

    def make(
        fmt: str,
        cams: Sequence[Cam] | None = None,
        *,
        name: str = "",
        imu: bool = False,
        chunk_bytes: int = 0,
    ) -> Path:
        if cams is None:
            cams = [
                Cam("/cam0/image_raw", regular(), index=0),
                Cam("/cam1/image_raw", regular(start=T0 + 7_000_000), index=1, encoding="jpeg"),
            ]
        stem = name or f"rec{next(counter)}_{fmt}"
        return write_bag(tmp_path / stem, fmt, cams, imu=imu, chunk_bytes=chunk_bytes)

    return make
