"""``manifest.json`` and ``manifest.csv`` beside every export: what each file holds.

Per set: id, trigger word, its start/end (audio seconds) and time ``t_ns`` (session
clock), decision, skew; per camera: stream, export camera name, frame index and header
stamp, file (relative to the export folder; for bags the bag), quality figures as stored
in the session (sharpness, corners, flags) and, for a frame left out, why.
The CSV has one row per set and camera, with the same values.
"""

from __future__ import annotations

import csv
import io
import json
from typing import TYPE_CHECKING, Any

from speechcal_core.fsutil import atomic_write_text

if TYPE_CHECKING:
    from pathlib import Path

    from speechcal_core.export.plan import Outcome, Plan

JSON_FILE = "manifest.json"
CSV_FILE = "manifest.csv"
CSV_COLUMNS = ("set_id", "word", "start_s", "end_s", "t_ns", "decision", "skew_ns", "stream",
               "camera", "index", "stamp_ns", "file", "sharpness", "corners", "flags",
               "skipped")


def manifest_document(
    plan: Plan, outcome: Outcome, cameras: dict[str, str], header: dict[str, Any]
) -> dict[str, Any]:
    """The manifest as one JSON-ready dict; ``header`` comes first (format, session...)."""
    sets = []
    for s in plan.sets:
        frames = []
        for pf in plan.frames_of(s.id):
            c = pf.choice
            key = (s.id, c.stream)
            frames.append({
                "stream": c.stream,
                "camera": cameras[c.stream],
                "index": pf.index,
                "stamp_ns": c.stamp_ns,
                "file": outcome.files.get(key),
                "sharpness": c.sharpness,
                "corners": c.corners,
                "flags": list(c.flags),
                **({"skipped": outcome.skipped[key]} if key in outcome.skipped else {}),
            })
        sets.append({
            "id": s.id,
            "word": s.trigger.word,
            # microseconds: no float noise such as 9.764999999999999 in the CSV
            "start_s": round(s.trigger.start_s, 6),
            "end_s": round(s.trigger.end_s, 6),
            "t_ns": s.t_ns,
            "name": plan.names[s.id],
            "decision": s.decision,
            "skew_ns": s.skew_ns,
            "frames": frames,
        })
    return {
        **header,
        "cameras": [{"stream": n, "camera": cameras[n]} for n in plan.streams],
        "sets": sets,
    }


def manifest_rows(document: dict[str, Any]) -> list[dict[str, Any]]:
    """One flat row per set and camera, keyed by :data:`CSV_COLUMNS`."""
    rows = []
    for s in document["sets"]:
        for f in s["frames"]:
            rows.append({
                "set_id": s["id"], "word": s["word"], "start_s": s["start_s"],
                "end_s": s["end_s"], "t_ns": s["t_ns"], "decision": s["decision"],
                "skew_ns": s["skew_ns"], "stream": f["stream"], "camera": f["camera"],
                "index": f["index"], "stamp_ns": f["stamp_ns"], "file": f["file"] or "",
                "sharpness": "" if f["sharpness"] is None else f["sharpness"],
                "corners": "" if f["corners"] is None else f["corners"],
                "flags": ";".join(f["flags"]), "skipped": f.get("skipped", ""),
            })
    return rows


def write_manifest(root: Path, document: dict[str, Any]) -> list[str]:
    """Write both files into ``root``; returns their names."""
    atomic_write_text(root / JSON_FILE,
                      json.dumps(document, indent=1, ensure_ascii=False) + "\n")
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=CSV_COLUMNS, lineterminator="\n")
    writer.writeheader()
    writer.writerows(manifest_rows(document))
    atomic_write_text(root / CSV_FILE, buf.getvalue())
    return [JSON_FILE, CSV_FILE]
