"""A walk with the ankle firmware in the loop, its nodes, faults and bus frames: :class:`Sil`."""

from __future__ import annotations

import functools
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd

from . import _walker
from ._walk import steps_frame

#: ``Sil.frames``' first columns; the decoded signals follow, one column per signal name.
FRAME_COLUMNS = ["time_s", "id", "dlc", "data", "error", "name", "sender"]


@functools.lru_cache(maxsize=1)
def database() -> Any:
    """The project's DBC (:func:`walker.dbc`) loaded by cantools (``cantools.database.Database``),
    loaded once."""
    import cantools

    return cantools.database.load_string(_walker.dbc(), database_format="dbc")


def _plain(value: Any) -> Any:
    """A decoded signal value: an enumerated one as its name (``"Enabled"``), else the number."""
    name = getattr(value, "name", None)
    return name if isinstance(name, str) else value


@dataclass(frozen=True)
class Sil:
    """A walk with the ankle firmware (two nodes on the simulated CAN bus) actuating the
    ankles: the ``walker sil --json`` report, the nodes, their faults and the bus frames.

    ``report`` is the ``walker sil --json`` object of the same run.
    """

    report: dict[str, Any] = field(repr=False)
    """The ``walker sil --json`` object."""
    raw_frames: dict[str, Any] = field(repr=False)
    """The bus frames as numpy arrays (``time_ns``, ``id``, ``dlc``, ``data`` n × 8,
    ``error``), undecoded: :attr:`frames` decodes them."""
    frames_cut_at_time_s: float | None = None
    """``None``: :attr:`frames` holds every bus event of the run; else the bus time [s] of the
    last one kept, where they reached ``max_frames`` (the walk went on)."""
    frames_not_kept: int = 0
    """Bus events past ``max_frames``, not kept."""

    @classmethod
    def from_parts(cls, report: dict[str, Any], frames: dict[str, Any]) -> Sil:
        """The run of a ``walker sil --json`` object and its frame arrays."""
        not_kept = int(frames["not_kept"])
        cut = None
        if not_kept and len(frames["time_ns"]):
            cut = float(frames["time_ns"][-1]) * 1e-9
        return cls(report, frames, cut, not_kept)

    @property
    def steps_completed(self) -> int:
        """Steps completed."""
        return int(self.report["steps_completed"])

    @property
    def failure(self) -> dict[str, Any] | None:
        """How the walk ended early (``kind``, ``step``, ``time_s``, ``detail``), or ``None``
        if it completed every step (a fall is a result: the command's exit code 3)."""
        return self.report["failure"]

    @property
    def fall_cause(self) -> dict[str, Any] | None:
        """The fault that ended the walk: the first safety-relevant fault a node raised at or
        before the failure (``side``, ``code``, ``detail``, ``t_s``, ``before_failure_s``), or
        ``None`` (no failure, or a fall no node saw coming)."""
        return self.report["fall_cause"]

    @property
    def gait(self) -> dict[str, Any] | None:
        """The firmware's gait over the last 10 steps before any emergency stop (speed, step
        length, period, ...), or ``None`` if no step completed."""
        return self.report["gait"]

    @property
    def ideal_gait(self) -> dict[str, Any]:
        """The ideal-actuator gait the walk started from."""
        return self.report["ideal_gait"]

    @property
    def start(self) -> dict[str, Any]:
        """What the walk started from (``gait_source``, ...)."""
        return self.report["start"]

    @property
    def emergency_stop_sent_s(self) -> float | None:
        """Walk time the host sent the emergency stop [s], or ``None``."""
        return self.report["emergency_stop_sent_s"]

    @property
    def bus_load(self) -> float:
        """Bus load [-]."""
        return float(self.report["bus_load"])

    @property
    def warnings(self) -> list[str]:
        """Differences between the scene's extension profile and the one the nodes report."""
        return list(self.report["warnings"])

    @property
    def firmware_params_written(self) -> dict[str, float]:
        """Firmware parameters written at start-up, by name [SI units]."""
        return dict(self.report["firmware_params_written"])

    @property
    def nodes(self) -> pd.DataFrame:
        """The final state of each node, one row per side (``Left``, ``Right``): ``state``,
        ``phase``, ``active_faults``, counters (``engagements``, ``frames_queued``, ...), the
        nested figures flattened (``parameters.taut_angle_rad``, ``actuator.peak_torque_n_m``,
        ``fault_raises.<code>``...)."""
        nodes = self.report["nodes"]
        table = pd.json_normalize([nodes[side] for side in nodes], sep=".")
        table.index = pd.Index(list(nodes), name="side")
        return table

    @property
    def node_faults(self) -> pd.DataFrame:
        """Every fault a node raised or cleared, in time order: ``time_s`` (tick time),
        ``side``, ``fault`` (``EncoderStuck``, ``PeerHeartbeatLost``, ...), ``raised`` (False:
        cleared), ``detail`` (the offending raw value)."""
        rows = [
            {
                "time_s": f["t_s"],
                "side": f["side"],
                "fault": f["code"],
                "raised": f["raised"],
                "detail": f["detail"],
            }
            for f in self.report["node_faults"]
        ]
        return pd.DataFrame(rows, columns=["time_s", "side", "fault", "raised", "detail"])

    @property
    def steps(self) -> pd.DataFrame:
        """One row per step kept (``keep_steps``), as :attr:`Walk.steps`."""
        return steps_frame(self.report["steps"])

    @property
    def sensor_faults_applied(self) -> pd.DataFrame:
        """Injected encoder faults that took effect: ``side``, ``kind``, ``t_s``."""
        return pd.DataFrame(self.report["sensor_faults_applied"])

    @functools.cached_property
    def frames(self) -> pd.DataFrame:
        """The run's bus events, as ``walker sil --candump`` logs them, decoded with the
        project's DBC (:func:`walker.dbc`, by cantools): ``time_s`` (bus clock: a data frame at
        the end of its interframe space), ``id`` (arbitration id; an error frame or bus-off
        has ``CAN_ERR_FLAG`` 0x20000000 and its class bits), ``dlc``, ``data`` (hex),
        ``error``, ``name`` (the DBC message, ``Heartbeat_LEFT_ANKLE``...; ``None`` for an
        error frame or an unknown id), ``sender`` (the DBC node), then one column per signal
        name (``state``, ``uptime``, ``angle``...; enumerated values by name, ``NaN`` where the
        message has no such signal). Decoded on first access (about 25 µs a frame: half a minute for a million)."""
        raw = self.raw_frames
        db = database()
        decoded: dict[tuple[int, bytes], tuple[str | None, str | None, dict[str, Any]]] = {}
        rows = []
        ids = raw["id"].tolist()
        dlcs = raw["dlc"].tolist()
        errors = raw["error"].tolist()
        data = raw["data"]
        for i, (fid, dlc, err) in enumerate(zip(ids, dlcs, errors)):
            payload = data[i, :dlc].tobytes()
            key = (fid, payload)
            if key not in decoded:
                decoded[key] = (None, None, {}) if err else _decode(db, fid, payload)
            name, sender, signals = decoded[key]
            rows.append(
                {"id": fid, "dlc": dlc, "data": payload.hex().upper(), "error": err, "name": name, "sender": sender}
                | signals
            )
        table = pd.DataFrame(rows, columns=None if rows else FRAME_COLUMNS[1:])
        table.insert(0, "time_s", np.asarray(raw["time_ns"], dtype=np.float64) * 1e-9)
        return table

    def messages(self, name: str) -> pd.DataFrame:
        """The frames of one DBC message (e.g. ``"Heartbeat_LEFT_ANKLE"``) with only its
        signals' columns."""
        table = self.frames[self.frames["name"] == name]
        return table.dropna(axis=1, how="all")


def _decode(db: Any, frame_id: int, payload: bytes) -> tuple[str | None, str | None, dict[str, Any]]:
    """The message's name, its sender and its signals (``{}`` if the id is not the DBC's or
    the data do not decode)."""
    try:
        message = db.get_message_by_frame_id(frame_id)
    except KeyError:
        return None, None, {}
    sender = message.senders[0] if message.senders else None
    try:
        values = message.decode(payload, decode_choices=True, scaling=True)
    except Exception:  # a corrupted or short frame: named, not decoded
        return message.name, sender, {}
    return message.name, sender, {k: _plain(v) for k, v in values.items()}
