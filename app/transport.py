"""Play / pause with the sound: the playhead follows the audio output, a playhead moved
while playing restarts the sound (throttled), and W plays one set's trigger word."""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import TYPE_CHECKING

from PySide6.QtCore import QObject, Qt, QTimer, Signal
from PySide6.QtWidgets import QPushButton, QWidget

from app.audio_player import AudioPlayer
from speechcal_core.audio.playback import RestartThrottle, word_span

if TYPE_CHECKING:
    from speechcal_core.review.model import ReviewModel

#: the play button's text and tooltip, stopped and playing
PLAY_STATES = {False: ("▶ play", "play from the playhead, with the sound  (Space)"),
               True: ("❚❚ pause", "pause  (Space)")}
#: what W says with no frame set at the playhead (taken back once one is there)
NO_SET_TO_HEAR = "no frame set at the playhead: J / K go to one"
#: play from a playhead this close to the session's end starts again from its start
END_SLACK_NS = 100_000_000
STEP_MS = 40  # how often the playhead follows the sound


class Transport(QObject):
    """The window's playback: its button (see :meth:`make_button`) shows and toggles
    it, ``player`` makes the sound, and the model's playhead follows. ``say`` puts a line
    on the status line."""

    #: play started (True) or paused (False): what a tile shows depends on it (a frame
    #: dropped while playing holds the earlier image dimmed; paused, the tile says so)
    state_changed = Signal(bool)

    def __init__(self, parent: QWidget, say: Callable[[str], None]) -> None:
        super().__init__(parent)
        self.say = say
        self.model: ReviewModel | None = None
        self.playing = False
        self._stepping = False  # the playhead moves because play goes on (not a jump)
        self._started = (0.0, 0)  # (monotonic time, playhead) the clock counts from
        self.player = AudioPlayer(parent, say=say)
        self.button: QPushButton | None = None
        self._timer = QTimer(self)
        self._timer.setInterval(STEP_MS)
        self._timer.timeout.connect(self._step)
        self._restarts = RestartThrottle()  # a playhead dragged while playing
        self._restart_timer = QTimer(self)
        self._restart_timer.setSingleShot(True)
        self._restart_timer.timeout.connect(self._restart_sound)

    def make_button(self) -> QPushButton:
        """A new play / pause button (each review page has its own), shown from now on."""
        self.button = QPushButton()
        self.button.setFocusPolicy(Qt.FocusPolicy.NoFocus)
        self.button.clicked.connect(lambda _=False: self.toggle())
        self._show_state()
        return self.button

    def follow(self, model: ReviewModel) -> None:
        """Play ``model``'s session from now on (stopped first if playing)."""
        self.stop()
        self.model = model
        self.player.set_source(model.session.audio, model.session.audio_channel)
        model.connect("playhead", self._on_playhead_moved)

    def stop(self) -> None:
        """Pause if playing."""
        if self.playing:
            self.toggle()

    def toggle(self) -> None:
        """Space: play from the playhead, with the audio from there; again: pause."""
        if self.model is None:
            return
        start_ns, end_ns = self.model.time_range_ns()
        if not self.playing and self.model.playhead_ns >= end_ns - END_SLACK_NS:
            self.model.set_playhead(start_ns)  # play at the end: from the start again
        self.playing = not self.playing
        self._show_state()
        self._restart_timer.stop()
        self._restarts.cancel()
        if self.playing:
            self._timer.start()
            self._play_sound()
        else:
            self._timer.stop()
            self.player.stop()
        self.state_changed.emit(self.playing)

    def hear_word(self) -> None:
        """W: play the trigger word of the set under the playhead (the playhead stays)."""
        model = self.model
        if model is None:
            return
        frame_set = model.set_at_playhead()
        if frame_set is None:
            self.say(NO_SET_TO_HEAR)
            return
        self.stop()
        span = word_span(frame_set.trigger)
        if not self.player.play(span.start_s, span.end_s):
            return
        if span.by_hand:
            text = (f"set {frame_set.id} was added by hand and has no word bounds: playing "
                    f"{span.end_s - span.start_s:.0f} s around its time")
        else:
            text = (f"playing set {frame_set.id}'s word \"{frame_set.trigger.word}\" "
                    f"({span.end_s - span.start_s:.2f} s with margins)")
        self.say(text)

    def shutdown(self) -> None:
        """Stop the clocks and the sound for good (the window closes)."""
        self._timer.stop()
        self._restart_timer.stop()
        self.player.shutdown()

    def _show_state(self) -> None:
        if self.button is None:
            return
        text, tip = PLAY_STATES[self.playing]
        self.button.setText(text)
        self.button.setToolTip(tip)

    def _play_sound(self, quiet: bool = False) -> None:
        """The audio from the playhead on (until paused), and the clock the playhead
        follows where there is no sound; ``quiet``: say nothing when there is no sound
        (it was said when play started)."""
        assert self.model is not None
        now = time.monotonic()
        self._started = (now, self.model.playhead_ns)
        t_s = float(self.model.session.sync.to_audio(self.model.playhead_ns))
        self._restarts.done(now)
        if not self.player.play(t_s, quiet=True, lead_in=True) and not quiet:
            # the playhead plays on by the clock: said so ("cannot play the audio: … not
            # found" alone, with the playhead running, read as if nothing played)
            self.say(f"playing without sound: {self.player.unavailable}")

    def _step(self) -> None:
        """The playhead follows the sound: where the audio output has got to, so what is
        seen is what is heard; by the clock only while nothing plays (no audio output,
        or past the audio's end). It waits while a restart is due (see
        :meth:`_on_playhead_moved`)."""
        if self.model is None or self._restarts.pending:
            return
        now = time.monotonic()
        heard = self.player.heard_s()
        if heard is not None:
            target = int(self.model.session.sync.to_session(heard))
            self._started = (now, target)  # the clock goes on from here if sound ends
        else:
            t0, p0 = self._started
            target = p0 + int((now - t0) * 1e9)
        if target >= self.model.time_range_ns()[1]:
            self.toggle()
        self._stepping = True
        try:
            self.model.set_playhead(target)
        finally:
            self._stepping = False

    def _on_playhead_moved(self, playhead_ns: int) -> None:
        """The operator moved the playhead (or the offset) while playing: play on from
        there, the sound too; a drag restarts the sound at most once per
        :data:`~speechcal_core.audio.playback.RESTART_INTERVAL_S`, from where the
        playhead is by then."""
        if not self.playing or self._stepping:
            return
        wait = self._restarts.request(time.monotonic())
        if wait == 0:
            self._play_sound(quiet=True)
        elif wait is not None:
            self._restart_timer.start(max(1, round(wait * 1000)))

    def _restart_sound(self) -> None:
        """A restart waited for the drag's interval: the sound from the playhead now."""
        if self.playing and self.model is not None:
            self._play_sound(quiet=True)
        else:
            self._restarts.cancel()
