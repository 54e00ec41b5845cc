"""Index cache beside the recording (or under the user cache dir), keyed by size and mtime."""

from __future__ import annotations

import hashlib
import json
import os
import tempfile
import zipfile
from pathlib import Path

import numpy as np

from speechcal_core.sources.scan import FileScan, TopicScan

#: 2: image topics without any message are kept (``FileScan.empty_topics``)
#: 3: a ROS1 bag closed without any message is whole (--scan cached it as truncated)
VERSION = 3
_ARRAYS = ("stamps", "log_times", "offsets", "chunks", "sizes")


#: the ending of an index cached beside its recording (``.NAME`` + this)
INDEX_SUFFIX = ".speechcal-index.npz"


def user_cache_dir() -> Path:
    """``$XDG_CACHE_HOME/speechcal/index`` (default ``~/.cache/speechcal/index``)."""
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "speechcal" / "index"


def cache_paths(path: Path) -> list[Path]:
    """Where the index of ``path`` may be cached: beside it first, then the user cache."""
    path = Path(path).resolve()
    beside = path.parent / f".{path.name}{INDEX_SUFFIX}"
    digest = hashlib.sha1(os.fsencode(path)).hexdigest()[:16]  # any name the OS has
    return [beside, user_cache_dir() / f"{path.name}.{digest}.npz"]


def _key(path: Path) -> dict[str, int]:
    st = os.stat(path)
    return {"version": VERSION, "size": st.st_size, "mtime_ns": st.st_mtime_ns}


def load(path: Path) -> FileScan | None:
    """The cached index of ``path`` if one matches its current size and mtime."""
    key = _key(path)
    for candidate in cache_paths(path):
        if not candidate.is_file():
            continue
        try:
            with np.load(candidate, allow_pickle=False) as z:
                meta = json.loads(bytes(z["meta"]).decode())
                if meta.get("key") != key:
                    continue
                topics = []
                for k, t in enumerate(meta["topics"]):
                    ts = TopicScan(**t)
                    for name in _ARRAYS:
                        setattr(ts, name, np.asarray(z[f"t{k}_{name}"], np.int64))
                    topics.append(ts)
                return FileScan(
                    topics=topics,
                    chunk_rows=[
                        (int(a), int(b), int(c))
                        for a, b, c in np.asarray(z["chunk_table"], np.int64).reshape(-1, 3)
                    ],
                    chunk_compression=list(meta["chunk_compression"]),
                    notes=list(meta["notes"]),
                    other_topics=list(meta["other_topics"]),
                    empty_topics=list(meta.get("empty_topics", [])),
                )
        except (OSError, ValueError, KeyError, TypeError, zipfile.BadZipFile):
            continue
    return None


def save(path: Path, scan: FileScan) -> Path | None:
    """Write the index atomically beside ``path``, else under the user cache; None if neither."""
    meta = {
        "key": _key(path),
        "topics": [
            {
                "topic": t.topic,
                "msgtype": t.msgtype,
                "serialization": t.serialization,
                "connection": t.connection,
                "encoding": t.encoding,
                "width": t.width,
                "height": t.height,
            }
            for t in scan.topics
        ],
        "chunk_compression": scan.chunk_compression,
        "notes": scan.notes,
        "other_topics": scan.other_topics,
        "empty_topics": scan.empty_topics,
    }
    arrays: dict[str, np.ndarray] = {
        "meta": np.frombuffer(json.dumps(meta).encode(), np.uint8),
        "chunk_table": scan.chunk_table,
    }
    for k, t in enumerate(scan.topics):
        for name in _ARRAYS:
            arrays[f"t{k}_{name}"] = getattr(t, name)
    for target in cache_paths(path):
        try:
            target.parent.mkdir(parents=True, exist_ok=True)
            fd, tmp = tempfile.mkstemp(prefix=target.name, suffix=".tmp", dir=target.parent)
        except OSError:
            continue
        try:
            os.fchmod(fd, 0o644)
            with os.fdopen(fd, "wb") as fh:
                np.savez(fh, **arrays)  # type: ignore[arg-type]
            os.replace(tmp, target)
            return target
        except OSError:
            Path(tmp).unlink(missing_ok=True)
    return None
