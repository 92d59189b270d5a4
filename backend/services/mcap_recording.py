"""What a run's MCAP recording is, whatever the run's kind, and how it is written (docs/service.md,
"Recordings").

A kind's export — a robot run's or a replay's (:mod:`backend.services.mcap_export`), a simulated
run's (:mod:`backend.services.mcap_sim`) — gathers the run's own channels that have a meaning for
it (:mod:`~backend.services.mcap_schemas`: a simulation has no commands, telemetry or link) as
field dicts on one clock, with :func:`poses` and :func:`touchdown` for the body's path and its
touchdowns; :func:`with_drawings` adds what Foxglove and Rerun draw from them
(:mod:`~backend.services.mcap_visuals`) and the chute the run climbed
(:mod:`~backend.services.mcap_world`); :func:`write_recording` writes the :class:`Recording`. A
channel a kind leaves out is not in its file at all (no schema, no channel); one it has is
registered even without messages.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable
from dataclasses import dataclass
from functools import partial
from typing import BinaryIO

import numpy as np
from sqlalchemy.orm import Session

from backend.store.models import Run
from experiments.manifest import json_safe

METADATA_NAME = "parkourlab.run"

Timed = list[tuple[int, object]]  # (log time [UTC ns], message), in the order they happened


@dataclass(frozen=True)
class Recording:
    """What a run's MCAP holds before it is written: each topic's messages as (log time [ns],
    message), in the order they happened — a dict of its fields on the channels of
    :mod:`~backend.services.mcap_schemas`, a protobuf message or a float on those of
    :mod:`~backend.services.mcap_visuals` — and the run's metadata (:func:`metadata_text`)."""

    run_id: int
    messages: dict[str, Timed]
    metadata: dict[str, str]

    def counts(self) -> dict[str, int]:
        return {topic: len(messages) for topic, messages in self.messages.items()}


def poses(times: Iterable[float], xs: Iterable[float], ys: Iterable[float],
          pitches: Iterable[float] | None = None) -> list[dict]:  # fmt: skip
    """``/tracker/pose``'s messages: the body at each time [s] at ``x``, ``y`` [m] in wall
    coordinates, its pitch [rad] absent where NaN or where there is none (``pitches`` None)."""
    times, xs, ys = (np.asarray(values, dtype=np.float64).tolist() for values in (times, xs, ys))
    pitches = [math.nan] * len(times) if pitches is None else np.asarray(pitches, dtype=np.float64).tolist()
    return [
        {"tracker_time": t, "x": x, "y": y, "pitch": pitch if math.isfinite(pitch) else None}
        for t, x, y, pitch in zip(times, xs, ys, pitches, strict=True)
    ]


def touchdown(stored: dict, control: dict | None, rises: list) -> dict:
    """``/touchdowns``' message of touchdown ``stored`` (a robot run's stored touchdown: ``index``,
    ``time`` [s], ``wall``, ``state``, heights [m], ``poses_fitted``) made with ``control``
    (``psi0_deg``, ``zeta0``; None: unknown), its rise the run's ``rises[index - 1]`` [l0]."""
    k = stored["index"]
    return {
        "index": k,
        "tracker_time": stored["time"],
        "wall": stored["wall"],
        "state": stored["state"],
        "body_height": stored["body_height"],
        "foot_height": stored["foot_height"],
        "poses_fitted": stored["poses_fitted"],
        "control": control,
        "rise": rises[k - 1] if 0 < k <= len(rises) else None,
    }


def with_drawings(session: Session, climbed: Run, frames: dict | None, messages: dict[str, Timed],
                  start_ns: int) -> dict[str, Timed]:  # fmt: skip
    """``messages`` (the run's own channels) with what is drawn from them and the chute run
    ``climbed`` climbed (``frames``: its body's heights ``y`` [m], for parallel walls' height), the
    chute once at the recording's start: its earliest message, ``start_ns`` with none."""
    from backend.services import mcap_visuals, mcap_world  # protobuf, Foxglove's schemas: loaded by exports only

    start = min((time for timed in messages.values() for time, _ in timed), default=start_ns)
    chute = mcap_world.messages(mcap_world.chute_of(session, climbed, frames), start)
    return messages | mcap_visuals.drawn(messages) | chute


def metadata_text(values: dict[str, object]) -> dict[str, str]:
    """The ``parkourlab.run`` Metadata record: text as it is, any other value as JSON text."""
    return {name: value if isinstance(value, str) else json.dumps(json_safe(value)) for name, value in values.items()}


def write_recording(recording: Recording, stream: BinaryIO) -> None:
    """The recording as MCAP on ``stream``: a schema and channel per topic it has (even one without
    messages; the run's own channels first, in :data:`~backend.services.mcap_schemas.TOPICS`' order,
    then :mod:`~backend.services.mcap_visuals`'), the metadata record, then every message in
    log-time order (at one time, in the order the channels are registered)."""
    from mcap.writer import Writer  # the exports load it, not the service's start
    from mcap_protobuf.schema import register_schema

    from backend.services import mcap_schemas, mcap_visuals

    writer = Writer(stream)
    writer.start(profile="", library="parkourlab")
    channels = {}
    for topic, name in mcap_schemas.TOPICS.items():
        if topic in recording.messages:
            schema_id = register_schema(writer, mcap_schemas.message_class(name))
            channel_id = writer.register_channel(topic, "protobuf", schema_id)
            channels[topic] = (channel_id, partial(mcap_schemas.encode, topic))
    channels |= mcap_visuals.register(writer, recording.messages)
    writer.add_metadata(METADATA_NAME, recording.metadata)
    timed = sorted(
        ((time, topic, sequence, message) for topic in channels
         for sequence, (time, message) in enumerate(recording.messages[topic])),
        key=lambda item: item[0],
    )  # fmt: skip
    for time, topic, sequence, message in timed:
        channel_id, encoder = channels[topic]
        writer.add_message(channel_id, log_time=time, data=encoder(message), publish_time=time, sequence=sequence)
    writer.finish()
