"""What a batch did: each unit's worst row, of the units it ran and of those it skipped (the batch's summary).

Public names
------------
BatchRun, KEPT
"""

from __future__ import annotations

from dataclasses import dataclass, field

#: verdicts from best to worst (a serial's summary is its worst row)
_RANK = {"pass": 0, "warn": 1, "fail": 2, "failed": 3, "error": 4}
#: what a :class:`BatchRun` keeps of each row
KEPT = ("serial", "order", "slot", "job", "sensor", "status", "exit_code", "verdict", "message")


@dataclass
class BatchRun:
    """What a batch did: each unit's worst row, of the units it ran and of those it skipped.

    A unit (serial) is kept as one small record, its worst row over its jobs and sensors (error, failed, fail,
    warn, pass; :data:`KEPT` without the figures, the message only where it does not pass): the table has every
    row, and the batch's memory stays flat however long the lot.

    Attributes
    ----------
    total : int
        Units (serials) in the manifest.
    """

    total: int = 0
    _ran: dict = field(default_factory=dict)
    _skipped: dict = field(default_factory=dict)

    def add(self, rows: list[dict], skipped: bool = False) -> None:
        """Keep the worst of ``rows`` per serial (units run now, or with ``skipped`` units skipped)."""
        _fold(self._skipped if skipped else self._ran, rows)

    @staticmethod
    def _first(kept: dict, status: str | None, verdict: str | None) -> list[dict]:
        out = []
        for serial, (_, order, slot, job, sensor, st, code, vd, message) in kept.items():
            if (status is None or st == status) and (verdict is None or vd == verdict):
                out.append({"serial": serial, "order": order, "slot": slot, "job": job, "sensor": sensor,
                            "status": st, "exit_code": code, "verdict": vd, "message": message})
        return out

    def units(self, status: str | None = None, verdict: str | None = None) -> list[dict]:
        """One row per unit (serial) run now (its worst), optionally only those of a ``status`` or ``verdict``."""
        return self._first(self._ran, status, verdict)

    def lot(self, status: str | None = None, verdict: str | None = None) -> list[dict]:
        """As :meth:`units`, over the units run now and those skipped: the state of the whole lot."""
        both = dict(self._skipped)
        for serial, kept in self._ran.items():
            if serial not in both or kept[0] >= both[serial][0]:
                both[serial] = kept
        return self._first(both, status, verdict)


def _fold(kept: dict, rows: list[dict]) -> None:
    """Fold ``rows`` into ``kept`` (serial -> (rank, KEPT values but the serial)): the worst row of each serial."""
    for r in rows:
        verdict = r.get("verdict")
        rank = _RANK.get(str(verdict), 0)
        have = kept.get(r["serial"])
        if have is None or rank > have[0]:
            kept[r["serial"]] = (rank, *(r.get(k) for k in KEPT[1:-1]), r.get("message") if rank else "")
