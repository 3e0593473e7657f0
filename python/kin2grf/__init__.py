"""kin2grf: ground reaction forces, centre of pressure and joint torques from motion-capture
markers alone (no force plates), as the command line computes them.

    import kin2grf
    r = kin2grf.estimate("walk.c3d", static="static.c3d", r=1000)
    r.table          # per-frame results (pandas DataFrame when pandas is present, else a dict)
    r.summary        # the --json summary as a dict
    v = kin2grf.validate("walk.c3d")            # against the trial's plates
    rows = kin2grf.batch("trials.txt", jobs=2)  # or client=dask.distributed.Client(...)

Keyword arguments are the command line's settings with '_' for '-' (``speed_gate_ratio=1``,
``paper=True``, ``grm_reference=(0, 0)``); their defaults are the command line's
(``kin2grf.settings()`` lists them). Bad input raises ``kin2grf.InputError`` (a ValueError) with
the command line's message.
"""

from __future__ import annotations

import os
from typing import Any, Iterable

try:
    import numpy as np
except ImportError as e:  # the module's arrays are numpy's
    raise ImportError("kin2grf's Python module needs numpy, which this interpreter does not have: run it with "
                      "/usr/bin/python3 after `bash scripts/setup.sh` (Debian's python3-numpy), or install numpy "
                      "into this interpreter (python3 -m pip install numpy)") from e

from . import _kin2grf
from ._kin2grf import InputError

__version__ = _kin2grf.__version__
__all__ = ["estimate", "validate", "batch", "info", "settings", "read_trial_list", "Estimate", "InputError", "__version__"]


def settings() -> list[dict]:
    """The settings estimate() and validate() take: name, whether it is a flag, default, help."""
    return [dict(d, name=d["name"].replace("-", "_")) for d in _kin2grf.settings_help()]


_NAMES = None


def _words(kwargs: dict) -> list[str]:
    """Keyword arguments -> the command line's words, refusing unknown names as Python does."""
    global _NAMES
    if _NAMES is None:
        _NAMES = {d["name"]: d["flag"] for d in settings()}
    words: list[str] = []
    for key, value in kwargs.items():
        if key not in _NAMES:
            raise TypeError(f"unexpected keyword argument '{key}' (kin2grf.settings() lists the settings)")
        flag = "--" + key.replace("_", "-")
        if value is None or value is False:
            continue
        if _NAMES[key]:
            if value is not True:
                raise TypeError(f"'{key}' is a flag: give True or False")
            words.append(flag)
        elif isinstance(value, (list, tuple, np.ndarray)):
            words += [flag, *(_text(v) for v in value)]
        else:
            words += [flag, _text(value)]
    return words


def _text(v: Any) -> str:
    if isinstance(v, (float, np.floating)):
        return repr(float(v))  # shortest text that reads back to the same double
    return os.fspath(v) if isinstance(v, os.PathLike) else str(v)


def _is_integer_column(name: str) -> bool:
    """The estimate table's frame numbers, contact states and solver iterations are integers."""
    return name in ("frame", "iterations") or name.startswith("contact_")


def _stance_curves(columns: list[str], values, plate_names: list[str] | None = None):
    """A stance-curves table (``--stance-curves``'s rows) as a DataFrame: the side as "right" /
    "left", a plate by its name, frame_first an integer (a dict of arrays without pandas)."""
    columns = list(columns)
    values = np.asarray(values, dtype=float).reshape(-1, len(columns))
    cols = {c: values[:, k] for k, c in enumerate(columns)}
    cols["side"] = np.where(cols["side"] == 0, "right", "left")
    cols["frame_first"] = cols["frame_first"].astype(np.int64)
    if plate_names is not None:
        cols["plate"] = np.asarray([plate_names[int(k)] for k in cols["plate"]], dtype=object)
    try:
        import pandas as pd
    except ImportError:
        return cols
    return pd.DataFrame(cols, columns=columns)


def _table(columns: list[str], values: np.ndarray):
    try:
        import pandas as pd
    except ImportError:
        return {c: values[:, k].astype(np.int64) if _is_integer_column(c) else values[:, k] for k, c in enumerate(columns)}
    df = pd.DataFrame(values, columns=columns)
    for c in columns:
        if _is_integer_column(c) and np.isfinite(df[c]).all():
            df[c] = df[c].astype(np.int64)
    return df


class Estimate:
    """One trial's estimate.

    columns, values: the per-frame table of ``kin2grf estimate --csv`` (same columns; full
    precision; NaN where the CSV has an empty cell). table: that as a pandas DataFrame (a dict
    of arrays without pandas). summary: the ``--json`` document. messages: what the method noted.
    """

    def __init__(self, d: dict, trial: str = "", words: list[str] | None = None):
        self.columns: list[str] = list(d["columns"])
        self.values: np.ndarray = np.asarray(d["values"])
        self._curves_columns: list[str] = list(d.get("stance_curves_columns", []))
        self._curves_values: np.ndarray = np.asarray(d.get("stance_curves_values", np.zeros((0, 0))))
        self.summary: dict = d["summary"]
        self.messages: list[str] = list(d["messages"])
        self._trial, self._words = trial, list(words or [])

    def write_opensim(self, folder: str | os.PathLike) -> list[str]:
        """Write the OpenSim set into `folder`, as ``kin2grf estimate --opensim`` does: TRIAL_grf.mot
        (OpenSim's frame, every frame of the trial), TRIAL_markers.trc, TRIAL_external_loads.xml.
        The estimate is made again from the same trial and settings (it is deterministic)."""
        return list(_kin2grf.estimate(self._trial, self._words, os.fspath(folder))["written"])

    def write_mot(self, path: str | os.PathLike, lab_frame: bool = False) -> str:
        """Write the GRF .mot, as ``kin2grf estimate -o`` does: OpenSim's frame over every frame of
        the trial (the OpenSim set's TRIAL_grf.mot), or with `lab_frame` the input's lab frame over the
        processed window."""
        return _kin2grf.estimate(self._trial, self._words, "", os.fspath(path), bool(lab_frame))["written"][-1]

    def write_c3d(self, path: str | os.PathLike) -> str:
        """Write the trial's markers with the estimated GRF as two force platforms (TYPE 2: 1 the
        right foot, 2 the left) and its gait events, Z up, as ``kin2grf estimate --c3d`` does, for
        Nexus, Visual3D, Mokka or ezc3d. The estimate is made again from the same trial and settings."""
        return _kin2grf.estimate(self._trial, self._words, "", "", False, os.fspath(path))["written"][-1]

    @property
    def table(self):
        return _table(self.columns, self.values)

    @property
    def stances(self):
        """Each stance's ground reaction parameters (the summary's ``stance_parameters``: the rows of
        ``kin2grf estimate --stances``, full precision), right and left in time order with a
        ``side`` column: a pandas DataFrame (a list of dicts without pandas)."""
        by_side = self.summary.get("stance_parameters", {})
        rows = [{"side": side, **p} for side in ("right", "left") for p in by_side.get(side, [])]
        rows.sort(key=lambda p: (p["start_s"], p["side"] != "right"))
        try:
            import pandas as pd
        except ImportError:
            return rows
        return pd.DataFrame(rows)

    @property
    def stance_curves(self):
        """Each complete stance time-normalised, 0 to 100 % of the stance (the rows of ``kin2grf
        estimate --stance-curves``, full precision): the force in body weights, the COP's progression,
        the hip, knee and ankle torques (N m/kg) and powers (W/kg), with ``model="3d"`` the knee adduction
        moment and every joint's 3D moment in each plane (``hip_frontal_Nm_per_kg``, ...), a ``side``
        column of "right" / "left": a pandas DataFrame (a dict of arrays without pandas)."""
        return _stance_curves(self._curves_columns, self._curves_values)

    def __getitem__(self, column: str) -> np.ndarray:
        return self.values[:, self.columns.index(column)]

    def __repr__(self) -> str:
        return f"<kin2grf.Estimate {self.values.shape[0]} frames, mass {self.summary.get('mass_kg')} kg>"


def estimate(trial: str | os.PathLike, opensim: str | os.PathLike | None = None, **settings) -> Estimate:
    """Estimate GRF, COP, GRM and joint torques of `trial` (C3D or TRC), as `kin2grf estimate`.
    `opensim`: a folder to write the OpenSim set into, as ``--opensim DIR`` does (TRIAL_grf.mot in
    OpenSim's frame, TRIAL_markers.trc, TRIAL_external_loads.xml)."""
    words = _words(settings)
    return Estimate(_kin2grf.estimate(os.fspath(trial), words, os.fspath(opensim) if opensim else ""), os.fspath(trial), words)


def validate(trial: str | os.PathLike, plates: str | os.PathLike | None = None, threshold: float = 20.0,
             zero_offset: str = "unloaded", sync: str | float = "none", timing: str = "auto", **settings) -> dict:
    """Estimate, then compare with the trial's plates (or `plates`, a GRF .mot or C3D), as
    `kin2grf validate`. Returns the ``--json`` document, with the estimate under "estimate".
    `sync`: "none" (compare as recorded; the marker-plate offset is reported under "sync"),
    "auto" (compare after shifting the plates by it) or a shift in seconds (+ when the plates led).
    `timing`: how onsets and offsets are timed, as ``--timing``: "auto" (the loading ramp's zero
    intercept for the onsets on a plate low-pass filtered before export, the threshold's crossings
    elsewhere), "crossing" or "ramp". Under "stance_curves": each scored plate stance time-normalised,
    the estimate's and the plate's side by side, as ``--stance-curves`` writes them (a pandas
    DataFrame; a dict of arrays without pandas)."""
    d = _kin2grf.validate(os.fspath(trial), _words(settings), os.fspath(plates) if plates else "", float(threshold), zero_offset,
                          _text(sync), timing)
    out = d["validation"]
    out["estimate"] = Estimate(d["estimate"], os.fspath(trial), _words(settings))
    out["stance_curves"] = _stance_curves(d["stance_curves_columns"], d["stance_curves_values"], d["plate_names"])
    return out


def info(path: str | os.PathLike, threshold: float = 20.0, zero_offset: str = "none") -> dict:
    """What ``kin2grf info FILE --json`` reports (docs/FORMATS.md): rates, frames, markers and their
    gaps, force plates and their loaded intervals, events, body mass, and the marker set ``estimate``
    would take (``info(f)["marker_set"]``: the preset recognised, or the mapping made from the labels)."""
    return _kin2grf.info(os.fspath(path), float(threshold), zero_offset)


def read_trial_list(path: str | os.PathLike) -> list[str]:
    """The trial lines of a trial-list file ('activity|lab|name|TRIAL [settings] [--plates F]')."""
    with open(path, encoding="utf-8") as f:
        return [line.rstrip("\n") for line in f if line.strip() and not line.startswith("#")]


def _batch_one(line: str, out_dir: str) -> dict:
    return _kin2grf.batch_lines([line], 1, out_dir)[0]


def batch(trials: str | os.PathLike | Iterable[str], jobs: int | None = None, client=None, out_dir: str = ""):
    """Run every trial (a trial-list file or its lines), as `kin2grf batch`: estimated, validated
    where it has plates, past failures (a row's "error"). Locally on `jobs` threads (default:
    every core), or on a dask.distributed `client`'s workers, one task per trial. Rows in the
    list's order: a pandas DataFrame when pandas is present, else a list of dicts."""
    lines = read_trial_list(trials) if isinstance(trials, (str, os.PathLike)) else list(trials)
    if client is None:
        rows = _kin2grf.batch_lines(lines, int(jobs or os.cpu_count() or 1), out_dir)
    else:
        futures = client.map(_batch_one, lines, out_dir=out_dir, pure=False)
        rows = client.gather(futures)
    try:
        import pandas as pd
    except ImportError:
        return rows
    # The CSV's column order (kin2grf batch --csv), then the row's other fields.
    first = [c for c in _kin2grf.batch_columns() if rows and c in rows[0]]
    rest = [c for c in (rows[0] if rows else {}) if c not in first]
    return pd.DataFrame(rows, columns=first + rest)


def _settings_doc() -> str:
    lines = ["", "Settings (keyword arguments; kin2grf.settings() lists them too):", ""]
    for d in settings():
        default = "" if d["flag"] or not d["default"] else f" (default {d['default']})"
        lines.append(f"    {d['name']}{' (flag)' if d['flag'] else ''}{default}: {d['help']}")
    return "\n".join(lines) + "\n"


# help(kin2grf.estimate) and help(kin2grf.validate) list every setting, from the command line's parser.
estimate.__doc__ = (estimate.__doc__ or "") + "\n" + _settings_doc()
validate.__doc__ = (validate.__doc__ or "") + "\n" + _settings_doc()
