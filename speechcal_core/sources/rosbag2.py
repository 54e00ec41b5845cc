"""ROS2 bags: sqlite3 storage (stamps read from a 12-byte blob prefix) and bag folders."""

from __future__ import annotations

import os
import sqlite3
import threading
from pathlib import Path
from typing import TYPE_CHECKING
from urllib.parse import quote

from speechcal_core.sources.errors import SourceError
from speechcal_core.sources.msgparse import STAMP_PREFIX, stamp_cdr
from speechcal_core.sources.scan import FileScan, TopicCollector, TopicScan, image_msgtype

if TYPE_CHECKING:
    from speechcal_core.sources.scan import MessageFile


def ros2_folder_files(folder: Path, *, scan: bool = False) -> list[MessageFile]:
    """The storage files of a ROS2 bag folder (split bags give several), in name order."""
    from speechcal_core.sources.mcap import McapFile

    files = sorted(p for p in folder.iterdir() if p.suffix in (".db3", ".mcap"))
    if not files:
        zst = [p.name for p in folder.iterdir() if p.name.endswith((".zstd", ".zst"))]
        if zst:
            raise SourceError(
                f"{folder}: bag files are zstd-compressed ({zst[0]}); "
                "decompress them first (`ros2 bag decompress` or `zstd -d`)"
            )
        raise SourceError(f"{folder}: no .db3 or .mcap files in this ROS2 bag folder")
    out: list[MessageFile] = []
    try:
        for p in files:
            out.append(Sqlite3File(p) if p.suffix == ".db3" else McapFile(p, scan=scan))
    except BaseException:
        for f in out:
            f.close()
        raise
    return out


#: what to do with a sqlite3 bag that cannot be read. A cut-short one cannot be repaired
#: here: its tables' interior pages lie past the cut, and Debian's sqlite3 3.40
#: ``.recover`` saved no message of one (a 142 MB bag cut at 50 MB)
CUT_SHORT_ADVICE = ("if it was cut short (the recorder stopped uncleanly, a copy broke "
                    "off), copy it again where it is whole; a sqlite3 bag cut short cannot "
                    "be read, while MCAP storage (ros2 bag record -s mcap) keeps one "
                    "readable with `speechcal index FILE --scan`")

#: the longest path (bytes) of a file that SQLite opens: its unix VFS takes 512 bytes,
#: which must also hold a rollback journal's name (the database's with "-journal")
SQLITE_PATH_MAX = 512 - len("-journal")


def sqlite_path_problem(path: Path) -> str:
    """Why SQLite cannot open ``path`` for its length ("" when it can): it counts the
    path where links lead, so a shorter link to the file does not help."""
    real = len(os.fsencode(path.resolve()))
    if real <= SQLITE_PATH_MAX:
        return ""
    return (f"its path is {real} bytes long, and SQLite opens no file whose path is longer "
            f"than {SQLITE_PATH_MAX} bytes (a link with a shorter path does not help: SQLite "
            "follows it)")


class Sqlite3File:
    """One rosbag2 ``.db3`` file; the index reads only each blob's first bytes."""

    def __init__(self, path: Path) -> None:
        self.path = Path(path)
        self.name = self.path.name
        if not self.path.is_file():
            raise SourceError(f"{self.path}: file not found; check the path")
        too_long = sqlite_path_problem(self.path)
        if too_long:
            raise SourceError(f"{self.path}: {too_long}; move the bag to a folder with a "
                              "shorter path")
        uri = f"file:{quote(str(self.path.resolve()))}?mode=ro&immutable=1"
        try:
            self.con = sqlite3.connect(uri, uri=True, check_same_thread=False)
            self.con.execute("SELECT count(*) FROM sqlite_master").fetchone()
        except sqlite3.DatabaseError as exc:
            raise SourceError(f"{self.path}: not a readable rosbag2 sqlite3 file ({exc}); "
                              f"{CUT_SHORT_ADVICE}") from None
        self.lock = threading.Lock()

    def _err(self, exc: Exception) -> SourceError:
        return SourceError(f"{self.path}: sqlite3 database is damaged ({exc}); "
                           f"{CUT_SHORT_ADVICE}")

    def scan(self) -> FileScan:
        """Index the image topics."""
        with self.lock:
            try:
                return self._scan()
            except sqlite3.DatabaseError as exc:
                raise self._err(exc) from None

    def _scan(self) -> FileScan:
        con = self.con
        tables = {r[0] for r in con.execute("SELECT name FROM sqlite_master WHERE type='table'")}
        if not {"topics", "messages"} <= tables:
            raise SourceError(f"{self.path}: not a rosbag2 file (no topics/messages "
                              f"tables); {CUT_SHORT_ADVICE}")
        cols = {r[1] for r in con.execute("PRAGMA table_info(topics)")}
        qos = "offered_qos_profiles" if "offered_qos_profiles" in cols else "''"
        defs: dict[str, str] = {}
        if "message_definitions" in tables:
            sql = "SELECT topic_type, encoded_message_definition FROM message_definitions"
            defs = dict(con.execute(sql))
        result = FileScan(topics=[])
        rows = con.execute(f"SELECT id, name, type, serialization_format, {qos} FROM topics")
        for tid, name, msgtype, fmt, qos_text in rows.fetchall():
            kind = image_msgtype(msgtype)
            if kind is None or fmt != "cdr":
                result.other_topics.append(f"{name} [{msgtype}]")
                continue
            conn = {
                "source_msgtype": msgtype,
                "msgdef": defs.get(msgtype, ""),
                "offered_qos_profiles": qos_text or "",
            }
            col = TopicCollector(TopicScan(name, kind, "cdr", conn))
            msgs = con.execute(
                "SELECT id, timestamp, length(data) FROM messages WHERE topic_id=? ORDER BY id",
                (tid,),
            ).fetchall()
            for rowid, log_time, size in msgs:
                if size < STAMP_PREFIX:
                    continue
                col.add(stamp_cdr(self._prefix(rowid)), log_time, rowid, -1, size)
            if col.rows:
                result.topics.append(col.finish())
            else:
                result.empty_topics.append(name)
        return result

    def _prefix(self, rowid: int, n: int = STAMP_PREFIX) -> bytes:
        # blobopen (Python >= 3.11) reads only the pages holding the prefix; substr() would
        # load the whole blob, overflow pages and all
        if hasattr(self.con, "blobopen"):
            with self.con.blobopen("messages", "data", rowid, readonly=True) as blob:
                return blob.read(n)
        row = self.con.execute(
            "SELECT substr(data, 1, ?) FROM messages WHERE id=?", (n, rowid)
        ).fetchone()
        return bytes(row[0])

    def attach(self, scan: FileScan) -> None:
        """Nothing to keep: rows are addressed by id."""

    def head(self, offset: int, chunk: int, n: int) -> bytes:
        """The first n bytes of message ``offset`` (only the pages holding them are read)."""
        with self.lock:
            try:
                return self._prefix(offset, n)
            except sqlite3.DatabaseError as exc:
                raise self._err(exc) from None

    def read(self, offset: int, chunk: int, size: int) -> bytes:
        """The message with row id ``offset``."""
        with self.lock:
            try:
                row = self.con.execute("SELECT data FROM messages WHERE id=?", (offset,)).fetchone()
            except sqlite3.DatabaseError as exc:
                raise self._err(exc) from None
        if row is None:
            raise SourceError(f"{self.path}: message {offset} is missing; re-index with --no-cache")
        return bytes(row[0])

    def close(self) -> None:
        """Close the database."""
        with self.lock:
            self.con.close()
