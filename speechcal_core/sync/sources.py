"""Where the sync audio comes from: a microphone file or an audio topic in the recording."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from speechcal_core.audio.bag_audio import BagAudio, audio_topics, load_bag_audio
from speechcal_core.audio.errors import AudioError
from speechcal_core.audio.loader import Audio, load_audio
from speechcal_core.audio.topic_file import is_audio_topic
from speechcal_core.sync.estimate import SyncResult
from speechcal_core.sync.stamped import stamped_sync, stamps_problem


def load_sync_audio(audio: str, recording: Sequence[str | Path], *,
                    channel: int | None = None, notes: list[str] | None = None
                    ) -> tuple[Audio, SyncResult | None]:
    """The audio, and for stamped bag audio the sync it implies (else None).

    ``audio`` is a file path, or an audio topic of the recording (e.g. ``/audio/audio``).
    Why a topic's stamps cannot time it (then the clap does) is added to ``notes``.
    """
    if not is_audio_topic(audio):
        return load_audio(Path(audio), channel=channel), None
    bag = load_topic_audio(audio, recording, channel=channel)
    problem = stamps_problem(bag)
    if problem and notes is not None:
        notes.append(problem)
    return bag.audio, stamped_sync(bag)


def load_topic_audio(topic: str, recording: Sequence[str | Path], *,
                     channel: int | None = None, all_channels: bool = False) -> BagAudio:
    """The audio topic ``topic`` of the recording's bags (``load_bag_audio``), or an
    AudioError naming what to give instead: the topic is not in the recording (its audio
    topics are listed), or the bags' audio topics cannot be read (a bag cut short)."""
    bags = [Path(r) for r in recording]
    try:
        topics = audio_topics(bags)
    except AudioError as exc:  # read by rosbags: a bag cut short is not (its images are)
        raise AudioError(f"{topic}: audio file not found, and the recording's audio topics "
                         f"cannot be read ({exc}); an audio topic is read only from a whole "
                         "bag: `rosbag reindex` a ROS1 bag cut short (`mcap recover` an MCAP "
                         "file), or give the microphone's audio file with --audio") from exc
    if topic not in topics:
        listed = ", ".join(sorted(topics)) or "none"
        raise AudioError(f"{topic}: audio file not found, and not an audio topic of the "
                         f"recording either (audio topics: {listed})")
    return load_bag_audio(bags, topic, channel=channel, all_channels=all_channels)
