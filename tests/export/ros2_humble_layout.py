"""A ROS 2 bag folder as ROS 2 Humble's recorder lays it out, made from one rosbags wrote."""

from __future__ import annotations

import sqlite3
from pathlib import Path

from ruamel.yaml import YAML  # what rosbags reads and writes metadata with


def as_humble_records_it(bag: Path) -> None:
    """Rewrite the sqlite3 bag folder ``bag`` (rosbags' newer layout) as Humble writes one:
    no message definitions (Humble stores none, so a reader must know the types), no type
    description hashes, database schema 3, and metadata version 5, whose QoS profiles
    are one YAML string per topic."""
    (db,) = bag.glob("*.db3")
    con = sqlite3.connect(db)
    try:
        con.execute("DROP TABLE message_definitions")
        con.execute("ALTER TABLE topics DROP COLUMN type_description_hash")
        con.execute("UPDATE schema SET schema_version = 3, ros_distro = 'humble'")
        con.commit()
    finally:
        con.close()
    yaml = YAML(typ="safe")
    meta_path = bag / "metadata.yaml"
    meta = yaml.load(meta_path)
    info = meta["rosbag2_bagfile_information"]
    info["version"] = 5
    for key in ("custom_data", "ros_distro"):  # newer than Humble
        info.pop(key, None)
    for entry in info["topics_with_message_count"]:
        topic = entry["topic_metadata"]
        topic.pop("type_description_hash", None)
        if not isinstance(topic.get("offered_qos_profiles"), str):
            topic["offered_qos_profiles"] = ""
    yaml.dump(meta, meta_path)
