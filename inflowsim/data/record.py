"""Flight-test records (``record-format.md``): reading, writing, trim.

A :class:`Record` is immutable: arrays are read-only, and nothing here writes to
the file a record was read from.  Every format error raises
:class:`~inflowsim.errors.RecordError` with one line naming the file and what is
wrong (channel, row, metadata key).
"""
from __future__ import annotations

import io
import math
import weakref
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Mapping

import numpy as np

from ..errors import InputError, RecordError
from .. import channels as chan
from ..channels import CONTROLS, FLAP, INPUTS
from ..fileio import safe_write_text
from ..frozen import FrozenDict, ReadOnlyArrays, readonly
if TYPE_CHECKING:
    from ..model.params import Constants
from ..simulate.sampled import DEFAULT_HOLD, HOLDS

REQUIRED_META = ("omega", "mu", "a0", "solidity")
#: Record columns (``record-format.md``): from the one channel table, inputs in the
#: model's order (a file may hold them in any order).
INPUT_COLUMNS = INPUTS
FLAP_COLUMNS = FLAP
CONTROL_COLUMNS = CONTROLS
#: Sampling jitter tolerated, as a fraction of the mean step.
JITTER = 0.01
#: Sample steps of flight data [s]: 100 kHz to 1 Hz.  A step outside draws a warning
#: (``t`` in milliseconds gives a step of 10 "s" at 100 Hz).
DT_PLAUSIBLE = (1e-5, 1.0)
#: A record this fraction shorter than a band needs still passes (rounding of a
#: quoted band limit: the paper's 0.2256 Hz is the bin 6/26.6 = 0.22556 Hz).
BAND_ROUNDING = 0.01
#: Most samples a record that the package writes may hold (``flighttest``,
#: ``simulate``): 5.5 h at 100 Hz.  Checked before generating: a mistyped step must
#: not allocate gigabytes and run for hours.
MAX_SAMPLES = 2_000_000



def band_needs(band_hz) -> float:
    """Shortest record [s] that resolves the band ``(f1, f2)`` [Hz]: one period of
    ``f1`` (the transform's resolution ``1/T`` may not exceed the band's lower
    limit, else the band silently starts above it: a 3 s record kept 4 bins of
    the paper's band) and 3 transform frequencies between ``f1`` and ``f2``."""
    f1, f2 = (float(b) for b in band_hz)
    return max(1.0 / f1, 2.0 / (f2 - f1))


@dataclass(frozen=True, eq=False)
class Record(ReadOnlyArrays):
    """One run: time ``t`` [s], channels by name (SI, totals), metadata.

    Attributes
    ----------
    t : ndarray, shape (N,)
        Sample times [s].
    channels : mapping of str to ndarray
        Channels by canonical name, totals in SI (angles [rad], rates [rad/s],
        accelerations [rad/s^2], velocities and inflow over ``Omega R`` [-]).
    meta : mapping of str to str
        The ``# key: value`` metadata (``omega`` [rad/s], ``mu`` [-], ``hold`` ...).
    source : str
        Where it was read from.
    order : tuple of str
        The columns' order as read.
    """

    t: np.ndarray
    channels: Mapping[str, np.ndarray]
    meta: Mapping[str, str]
    source: str = "<memory>"
    order: tuple = field(default=())

    @classmethod
    def from_arrays(cls, t, channels: Mapping, meta: Mapping, source="<memory>"):
        ch = {k: readonly(v) for k, v in channels.items()}
        rec = cls(readonly(t), FrozenDict(ch), FrozenDict(
            {k: str(v) for k, v in meta.items()}), source, tuple(ch))
        rec.check()
        return rec

    def to_json(self) -> dict:
        """The record as JSON-ready data (every float exact through ``repr``):
        ``{"source", "meta", "t", "channels": {name: [...]}}`` in column order;
        :meth:`from_json` reads it back."""
        return {"source": self.source, "meta": dict(self.meta), "t": self.t.tolist(),
                "channels": {k: self.channels[k].tolist() for k in self.order}}

    @classmethod
    def from_json(cls, doc: Mapping) -> "Record":
        """A record from :meth:`to_json` data (checked as a file would be)."""
        try:
            return cls.from_arrays(doc["t"], doc["channels"], doc["meta"],
                                   doc.get("source", "<json>"))
        except (KeyError, TypeError, ValueError) as exc:
            raise RecordError(f"record JSON: {exc}") from None

    # -- metadata -----------------------------------------------------------
    def _meta_float(self, key):
        if key not in self.meta:
            raise RecordError(f"{self.source}: missing required metadata '# {key}: ...'")
        try:
            v = float(self.meta[key])
        except ValueError:
            raise RecordError(f"{self.source}: metadata {key} = {self.meta[key]!r} "
                              "is not a number") from None
        if not math.isfinite(v):
            raise RecordError(f"{self.source}: metadata {key} is not finite")
        return v

    def base_constants(self) -> Constants:
        """Aircraft constants from the metadata (no trim)."""
        from ..errors import InputError
        vals = {k: self._meta_float(k) for k in REQUIRED_META}
        if "radius" in self.meta:
            vals["radius"] = self._meta_float("radius")
        if "hub" in self.meta:
            vals["hub"] = self.meta["hub"]
        try:
            # imported here: the model package is not needed to read a record's samples
            from ..model.params import Constants
            return Constants.from_mapping(vals)
        except InputError as exc:
            raise RecordError(f"{self.source}: metadata {exc}") from None

    @property
    def constants(self) -> Constants:
        """Aircraft constants from the metadata, with the record's trim totals
        (:func:`find_trim`) for effects linearised about trim."""
        return self.base_constants().with_trim(find_trim(self).values)

    @property
    def hold(self) -> str:
        """Intersample behaviour of the inputs (``# hold:``; ``record-format.md``):
        ``continuous`` (samples of continuous signals, the default: measured
        data), ``zoh`` (held over each sample) or ``foh`` (linear between samples)."""
        v = self.meta.get("hold", DEFAULT_HOLD).strip().lower()
        if v not in HOLDS:
            raise RecordError(f"{self.source}: metadata hold = {self.meta['hold']!r}: "
                              f"choose {', '.join(HOLDS)}")
        return v

    def hold_or(self, override=None) -> str:
        """``override`` (a ``--hold`` option) if given, else :attr:`hold`."""
        if override is None:
            return self.hold
        if override not in HOLDS:
            raise RecordError(f"hold {override!r}: choose {', '.join(HOLDS)}")
        return override

    @property
    def dt(self) -> float:
        return float((self.t[-1] - self.t[0]) / (len(self.t) - 1))

    @property
    def duration(self) -> float:
        """Length ``N dt`` [s]: the transform resolution is ``1/duration``."""
        return len(self.t) * self.dt

    def __len__(self):
        return len(self.t)

    def __getitem__(self, name) -> np.ndarray:
        try:
            return self.channels[name]
        except KeyError:
            raise RecordError(f"{self.source}: no column {name!r} "
                              f"(has {', '.join(self.order)})") from None

    # -- checks ---------------------------------------------------------------
    def check(self):
        src = self.source
        for k in REQUIRED_META:
            self._meta_float(k)
        t = self.t
        if len(t) < 4:
            raise RecordError(f"{src}: only {len(t)} samples; need at least 4")
        for name, v in [("t", t), *self.channels.items()]:
            if len(v) != len(t):
                raise RecordError(f"{src}: column {name} has {len(v)} values, t has {len(t)}")
            bad = np.flatnonzero(~np.isfinite(v))
            if bad.size:
                i = bad[0]
                raise RecordError(f"{src}: column {name} has a NaN or infinite value "
                                  f"at data row {i + 1} (t = {t[i] if name != 't' else 'n/a'})")
            big = np.flatnonzero(np.abs(v) > chan.LIMIT)
            if big.size:
                i = big[0]
                raise RecordError(f"{src}: column {name} = {v[i]:.6g} at data row {i + 1} "
                                  f"is beyond any physical value (|x| > {chan.LIMIT:g}); "
                                  "check the column's unit")
        d = np.diff(t)
        if np.any(d <= 0):
            i = int(np.flatnonzero(d <= 0)[0])
            raise RecordError(f"{src}: t is not strictly increasing at data row {i + 2} "
                              f"(t = {t[i + 1]:.10g} after {t[i]:.10g})")
        mean = (t[-1] - t[0]) / (len(t) - 1)
        k = np.arange(len(t))
        jit = np.abs(t - (t[0] + k * mean))
        if np.max(np.abs(d - mean)) > JITTER * mean and np.max(jit) > JITTER * mean:
            i = int(np.argmax(np.abs(d - mean)))
            raise RecordError(f"{src}: t is not uniformly sampled: step {d[i]:.6g} s at "
                              f"data row {i + 2} against mean {mean:.6g} s (tolerance "
                              f"{JITTER:.0%}); resample it first")
        self.base_constants()
        self.hold
        _trim_window_meta(self)
        return self

    def warnings(self) -> list[str]:
        """Plausibility warnings (a wrong unit, a wrong column): values no rotor in
        flight gives, constants outside the usual range.  Empty for a sane record."""
        out = [f"{self.source}: {w}" for w in self.base_constants().warnings()]
        lo, hi = DT_PLAUSIBLE
        if not lo <= self.dt <= hi:
            unit = "milliseconds" if self.dt > hi else "another unit"
            out.append(f"{self.source}: the sample step is {self.dt:g} s, outside the "
                       f"{lo:g}-{hi:g} s of flight data: is t in {unit}? (t is in "
                       "seconds)")
        for name, v in self.channels.items():
            ch = chan.BY_NAME.get(name)
            if ch is None or not len(v):
                continue
            m = float(np.max(np.abs(v)))
            if m > ch.plausible:
                hint = " (degrees instead of radians?)" if ch.unit == "rad" and \
                    m < 100 * ch.plausible else ""
                out.append(f"{self.source}: {name} reaches {m:.4g} {ch.unit}, beyond what "
                           f"a rotor in flight gives (|{name}| < {ch.plausible:g} "
                           f"{ch.unit}){hint}")
        return out

    def require(self, columns):
        """Raise naming the first of ``columns`` the record lacks."""
        for c in columns:
            if c not in self.channels:
                raise RecordError(f"{self.source}: the model needs column {c!r}, "
                                  "which the record lacks")
        return self

    def require_measured(self, columns=FLAP):
        """Raise naming the first of ``columns`` that is missing or constant over the
        whole record (a dead sensor): there is nothing to compare a model with."""
        self.require(columns)
        for c in columns:
            v = self.channels[c]
            if np.ptp(v) == 0.0:
                raise RecordError(f"{self.source}: column {c} is constant ({v[0]:g}) over "
                                  "the whole record: a dead or unconnected sensor, "
                                  "nothing to compare the model with")
        return self

    def check_band(self, band_hz):
        """Refuse a band the record cannot resolve: beyond Nyquist, or a record
        shorter than the band needs (:func:`band_needs`)."""
        f1, f2 = band_hz
        df = 1.0 / self.duration
        nyq = 0.5 / self.dt
        if not (0 < f1 < f2):
            raise RecordError(f"band {f1:g}-{f2:g} Hz: need 0 < f1 < f2")
        if f2 > nyq:
            raise RecordError(f"band upper limit {f2:g} Hz is above the Nyquist frequency "
                              f"{nyq:g} Hz of {self.source}")
        need = band_needs(band_hz)
        if self.duration < need * (1.0 - BAND_ROUNDING):
            raise RecordError(f"{self.source}: record too short for the band {f1:g}-{f2:g} "
                              f"Hz: {self.duration:.4g} s (resolution {df:.4g} Hz), the "
                              f"band needs at least {need:.4g} s (a period of its lower "
                              "limit, and 3 transform frequencies in it)")
        return self

    # -- derived ----------------------------------------------------------------
    def with_channels(self, **cols) -> "Record":
        """A new record with channels replaced or added (never in place)."""
        ch = dict(self.channels)
        ch.update(cols)
        order = self.order + tuple(k for k in cols if k not in self.order)
        r = Record(self.t, FrozenDict({k: readonly(v) for k, v in ch.items()}),
                   self.meta, self.source, order)
        return r.check()

    def with_meta(self, **meta) -> "Record":
        m = dict(self.meta)
        m.update({k: str(v) for k, v in meta.items()})
        return Record(self.t, self.channels, FrozenDict(m), self.source, self.order)


# -- trim ---------------------------------------------------------------------------
#: The quiet window ends this long before the first control movement [s]: a pilot's
#: input is a smooth signal, so the rotor answers its onset before it is detectable.
TRIM_MARGIN = 0.2
#: Fewer quiet samples than this: no trim can be taken from the record itself.
MIN_TRIM_SAMPLES = 5
#: A quiet lead-in shorter than this [s] gives a trim, with a warning.
SHORT_TRIM = 0.5
#: Consecutive samples a control's departure must hold to be a movement
#: (:func:`first_movement`): a single noise sample is not one.
PERSIST = 3


@dataclass(frozen=True)
class Trim:
    """Trim values subtracted from the channels, and how they were found.

    ``method``: ``"quiet"`` (the automatic quiet lead-in) or ``"window"`` (given);
    ``t_start``, ``t_end`` [s] the window; ``n_samples`` in it; ``t_movement`` the
    first control movement found [s] (``None`` for a given window); ``warning``
    one line when the trim deserves the user's attention, else ``None``.

    Attributes
    ----------
    values : mapping of str to float
        Trim value per channel (SI, as the channels).
    method : {"quiet", "window"}
        How the window was found.
    t_end : float
        The window's end [s].
    n_samples : int
        Samples in the window [-].
    t_start : float
        The window's start [s].
    t_movement : float or None
        The first control movement [s] (``None`` for a given window).
    warning : str or None
        A short lead-in's warning.
    """

    values: Mapping[str, float]
    method: str
    t_end: float
    n_samples: int
    t_start: float = 0.0
    t_movement: float | None = None
    warning: str | None = None

    def describe(self) -> str:
        win = f"{self.t_start:.4g}-{self.t_end:.4g} s"
        if self.method == "quiet" and self.t_movement is None:
            return (f"mean over {win} ({self.n_samples} samples): the whole record, "
                    "in which no control moves")
        if self.method == "quiet":
            return (f"mean over {win} ({self.n_samples} samples): the quiet lead-in, "
                    f"ending {TRIM_MARGIN:g} s before the first control movement at "
                    f"{self.t_movement:.4g} s")
        return f"mean over the given window {win} ({self.n_samples} samples)"

    def as_dict(self) -> dict:
        return {"method": self.method, "window_s": [self.t_start, self.t_end],
                "n_samples": self.n_samples, "first_movement_s": self.t_movement,
                "description": self.describe(), "warning": self.warning}


def _trim_window_meta(rec: Record):
    v = rec.meta.get("trim_window")
    if v is None:
        return None
    try:
        a, b = (float(x) for x in v.replace(",", " ").split())
    except ValueError:
        raise RecordError(f"{rec.source}: metadata trim_window = {v!r}: give two times "
                          "in seconds, 'T0 T1'") from None
    return a, b


def first_movement(rec: Record) -> int | None:
    """Index of the first sample where a pilot control has left its initial value.

    Per control: baseline the median of the first 0.25 s, noise the robust spread
    of the first differences over the first second (their median absolute
    deviation, ``1.4826 MAD / sqrt 2``); moved where the departure exceeds
    ``max(6 noise, 1e-4 x the largest departure)`` (the onset of a smooth input,
    at one ten-thousandth of its size) on :data:`PERSIST` consecutive samples: one
    noise sample beyond the threshold (a 4-sigma sample at ``t = 0`` with the
    noise estimated a third low) is not a movement.  ``None`` where no control
    moves.
    """
    t = rec.t
    first = None
    n_base = max(3, int(np.searchsorted(t, t[0] + 0.25)))
    n_noise = max(8, int(np.searchsorted(t, t[0] + 1.0)))
    for c in CONTROL_COLUMNS:
        if c not in rec.channels:
            continue
        v = rec[c]
        base = float(np.median(v[:n_base]))
        d = np.diff(v[:n_noise])
        noise = 1.4826 * float(np.median(np.abs(d - np.median(d)))) / np.sqrt(2.0)
        dep = np.abs(v - base)
        big = float(dep.max())
        if big == 0.0:
            continue
        out = dep > max(6.0 * noise, 1e-4 * big)
        if out.size >= PERSIST:
            held = np.convolve(out, np.ones(PERSIST, dtype=int), "valid") == PERSIST
        else:
            held = out & out.all()
        moved = np.flatnonzero(held)
        if not moved.size and _moves_from_start(v, noise, big):
            moved = np.array([0])
        if moved.size and (first is None or moved[0] < first):
            first = int(moved[0])
    return first


def _moves_from_start(v, noise: float, big: float) -> bool:
    """A control already moving in its first second: the spread of its first
    differences there (``noise``, which would be the sensor's noise in a quiet
    lead-in) is three times that of white noise measured by the second differences
    over the whole record, and its excursion ``big`` is beyond six of the latter
    (issue #37: such a control was called constant)."""
    if v.size < 8:
        return False
    d2 = np.diff(v, 2)
    white = 1.4826 * float(np.median(np.abs(d2 - np.median(d2)))) / np.sqrt(6.0)
    return noise > 3.0 * white and big > 6.0 * white


def require_control_movement(rec: Record) -> Record:
    """Raise (:class:`RecordError`) when no pilot control moves in ``rec``
    (:func:`first_movement`): nothing excites the rotor, so there is no response to
    fit or compare (a record of the trim only, or the wrong file)."""
    if first_movement(rec) is None:
        have = [c for c in CONTROL_COLUMNS if c in rec.channels]
        what = f"{', '.join(have)} constant" if have else "no control column"
        raise RecordError(f"{rec.source}: no control moves ({what} over the whole "
                          "record): nothing excites the rotor, so there is no response "
                          "to fit or compare")
    return rec


def find_trim(rec: Record, window=None) -> Trim:
    """Trim = the mean of each channel over a quiet window.

    ``window = (t0, t1)`` [s] gives it; else the record's ``# trim_window: T0 T1``
    metadata; else the quiet lead-in: from the first sample to ``TRIM_MARGIN``
    before the first control movement (:func:`first_movement`).  A record whose
    controls never move is all trim.  Fewer than ``MIN_TRIM_SAMPLES`` quiet samples
    is an error naming the remedy; a lead-in shorter than ``SHORT_TRIM`` s is
    used with a warning.

    Parameters
    ----------
    rec : Record
        The record (totals).
    window : (float, float), optional
        The trim window ``(t0, t1)`` [s].
    """
    t = rec.t
    window = window if window is not None else _trim_window_meta(rec)
    if window is not None:
        t0, t1 = (float(x) for x in window)
        if not (np.isfinite(t0) and np.isfinite(t1) and t0 < t1):
            raise RecordError(f"{rec.source}: trim window {t0:g}-{t1:g} s: need T0 < T1")
        i0, i1 = int(np.searchsorted(t, t0)), int(np.searchsorted(t, t1, side="right"))
        if i1 - i0 < MIN_TRIM_SAMPLES:
            raise RecordError(f"{rec.source}: trim window {t0:g}-{t1:g} s holds "
                              f"{max(i1 - i0, 0)} samples; need at least "
                              f"{MIN_TRIM_SAMPLES} (the record spans {t[0]:g}-{t[-1]:g} s)")
        half = 0.5 * rec.dt                  # a window quoted to its end samples
        if t0 < t[0] - half or t1 > t[-1] + half:
            raise RecordError(f"{rec.source}: trim window [{t0:g}, {t1:g}] s reaches "
                              f"outside the record [{t[0]:g}, {t[-1]:g}] s; give a quiet "
                              "window inside it")
        method, move, warn = "window", None, None
    else:
        k = first_movement(rec)
        i0 = 0
        if k is None:
            i1, move = len(t), None
        else:
            move = float(t[k])
            i1 = int(np.searchsorted(t, move - TRIM_MARGIN, side="right"))
        if i1 < MIN_TRIM_SAMPLES and move is None:
            raise RecordError(
                f"{rec.source}: only {i1} samples, fewer than the {MIN_TRIM_SAMPLES} a "
                "trim needs")
        if i1 < MIN_TRIM_SAMPLES:
            raise RecordError(
                f"{rec.source}: no quiet lead-in: a control moves at t = {move:.4g} s, "
                f"leaving {i1} quiet samples; give the trim window (--trim-window T0 T1, "
                "or '# trim_window: T0 T1' in the record)")
        method = "quiet"
        span = float(t[i1 - 1] - t[0])
        warn = (None if span >= SHORT_TRIM else
                f"{rec.source}: the quiet lead-in is only {span:.3g} s ({i1} samples) "
                "before the first control movement: the trim is uncertain; give a "
                "trim window if the record has a longer quiet part")
    vals = {k: float(np.mean(v[i0:i1])) for k, v in rec.channels.items()}
    return Trim(FrozenDict(vals), method, float(t[i1 - 1]), i1 - i0,
                float(t[i0]), move, warn)


#: Per record, its perturbation arrays by (columns, trim values): a diagnosis fits
#: a record a dozen times, and each fit keeps the perturbations it was made from;
#: they share one read-only array instead of a full-length copy each.
_PERTURBATIONS: "weakref.WeakKeyDictionary[Record, dict]" = weakref.WeakKeyDictionary()


def perturbations(rec: Record, trim: Trim, names) -> np.ndarray:
    """Columns ``names`` minus trim, shape ``(N, len(names))`` (read-only)."""
    rec.require(names)
    key = (tuple(names), tuple(float(trim.values[c]) for c in names))
    cache = _PERTURBATIONS.setdefault(rec, {})
    out = cache.get(key)
    if out is None:
        out = np.column_stack([rec[c] - trim.values[c] for c in names])
        out.flags.writeable = False
        cache[key] = out
    return out


def model_inputs(rec: Record, model, trim: Trim) -> np.ndarray:
    """SI perturbation inputs in ``model.inputs`` order (record names).

    Parameters
    ----------
    rec : Record
        The record (totals, SI: angles [rad], rates [rad/s], accelerations [rad/s^2],
        velocities over ``Omega R`` [-]).
    model : Model
        The model whose ``inputs`` order the columns.
    trim : Trim
        The trim subtracted (:func:`find_trim`).
    """
    return perturbations(rec, trim, model.inputs)


# -- I/O ---------------------------------------------------------------------------
def header_meta(path) -> dict:
    """The ``# key: value`` lines at the top of a record, read without its data
    (``{}`` for a file that cannot be read: :func:`read_record` says why)."""
    meta = {}
    try:
        with open(path, encoding="utf-8-sig", errors="replace") as fh:
            for line in fh:
                if not line.startswith("#"):
                    if line.strip():
                        break
                    continue
                k, sep, v = line[1:].partition(":")
                if sep:
                    meta.setdefault(k.strip(), v.strip())
    except OSError:
        pass
    return meta


def read_record(path) -> Record:
    """Read a CSV record; raise :class:`RecordError` (one line) on any format error.

    The path is checked first (:func:`inflowsim.fileio.check_input_file`: a regular
    file within the size limit; a FIFO or device is refused before anything opens
    it).  The data rows are parsed by ``numpy.loadtxt`` as the file streams in (a
    2-hour record at 64 Hz: 350 MB and 2.5 s for the text, its lines and their
    floats held at once; now about twice the array); any row it refuses sends the
    file through :func:`parse_record`, which names the first bad line.

    Parameters
    ----------
    path : path-like
        The CSV record (``docs/record-format.md``).
    """
    from ..fileio import check_input_file, read_input_bytes
    p = Path(path)
    src = str(p)
    try:
        check_input_file(p, "record", "record")
    except InputError as exc:
        raise RecordError(str(exc)) from None
    try:
        with open(p, encoding="utf-8-sig", newline=None) as fh:
            rec = _read_streamed(fh, src)
        if rec is not None:
            return rec
    except (UnicodeDecodeError, ValueError):
        pass                                  # parse_record says what is wrong
    except OSError as exc:
        raise RecordError(f"{src}: cannot read ({exc.strerror})") from None
    try:
        raw = read_input_bytes(p, "record", "record")
    except InputError as exc:
        raise RecordError(str(exc)) from None
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise RecordError(f"{src}: not UTF-8 text (byte {exc.start})") from None
    del raw
    return parse_record(text, src)


def _read_streamed(fh, source: str) -> Record | None:
    """The record of an open text file, its rows parsed by ``numpy.loadtxt``;
    ``None`` (or ``ValueError``) where :func:`parse_record` must look."""
    head = []
    while True:
        ln = fh.readline()
        if not ln:
            return None                       # no header row: parse_record says so
        ln = ln.rstrip("\n")
        head.append(ln)
        if not (ln.startswith("#") or not ln.strip()):
            break
    meta, header, _ = _parse_head(head, source)
    import warnings
    with warnings.catch_warnings():      # no rows: parse_record says what is wrong
        warnings.simplefilter("ignore", UserWarning)
        data = np.loadtxt(fh, delimiter=",", comments=None, dtype=float, ndmin=2)
    if data.shape[0] == 0 or data.shape[1] != len(header):
        return None
    return _finish(data, header, meta, source)


def _parse_head(lines, source: str):
    """``(meta, header, i)``: the metadata lines and the header row ``lines[i]``."""
    meta: dict[str, str] = {}
    seen: dict[str, int] = {}
    i = 0
    while i < len(lines) and (lines[i].startswith("#") or not lines[i].strip()):
        ln = lines[i]
        if ln.startswith("#"):
            body = ln[1:].strip()
            if body:
                if ":" not in body:
                    raise RecordError(f"{source}: line {i + 1}: metadata must be "
                                      f"'# key: value', got {ln!r}")
                k, v = body.split(":", 1)
                k = k.strip()
                if k in meta:
                    raise RecordError(f"{source}: line {i + 1}: metadata {k!r} given "
                                      f"twice (first on line {seen[k]}); keep one")
                meta[k] = v.strip()
                seen[k] = i + 1
        i += 1
    if i >= len(lines):
        raise RecordError(f"{source}: no header row (expected 't,theta0,...')")
    header = [h.strip() for h in lines[i].split(",")]
    if len(header) == 1 and (sep := _other_separator(lines[i])):
        raise RecordError(f"{source}: line {i + 1}: columns separated by {sep}, not by "
                          "commas: a record is comma-separated (record-format.md)")
    if "t" not in header:
        raise RecordError(f"{source}: line {i + 1}: the header has no column 't' (time "
                          f"in seconds); got {lines[i][:60]!r}")
    dup = {h for h in header if header.count(h) > 1}
    if dup:
        raise RecordError(f"{source}: line {i + 1}: duplicate column {sorted(dup)[0]!r}")
    if any(not h for h in header):
        raise RecordError(f"{source}: line {i + 1}: empty column name in the header")
    return meta, header, i


def _finish(data, header, meta, source) -> Record:
    for k in REQUIRED_META:
        if k not in meta:
            raise RecordError(f"{source}: missing required metadata '# {k}: ...'")
    it = header.index("t")                   # columns may come in any order
    return Record.from_arrays(data[:, it], {h: data[:, c] for c, h in enumerate(header)
                                            if c != it}, meta, source)


def parse_record(text: str, source: str = "<text>") -> Record:
    lines = text.splitlines()
    meta, header, i = _parse_head(lines, source)
    # straight into one float array: a list of rows of Python floats took five times
    # the array's memory (735 MB for a 2-hour record at 64 Hz)
    data = np.empty((len(lines) - i - 1, len(header)))
    n_rows = 0
    for j in range(i + 1, len(lines)):
        ln = lines[j]
        if not ln.strip():
            continue
        cells = ln.split(",")
        if len(cells) != len(header):
            raise RecordError(f"{source}: line {j + 1}: {len(cells)} values, the header "
                              f"has {len(header)} columns")
        try:
            data[n_rows] = [float(c) for c in cells]
        except ValueError:
            bad = next(k for k, c in enumerate(cells) if not _isfloat(c))
            raise RecordError(f"{source}: line {j + 1}: column {header[bad]}: "
                              f"{cells[bad].strip()!r} is not a number") from None
        n_rows += 1
    if not n_rows:
        raise RecordError(f"{source}: no data rows")
    return _finish(data[:n_rows], header, meta, source)


#: Separators other than the comma that spreadsheets write, by name.
_SEPARATORS = {";": "semicolons", "\t": "tabs", "|": "vertical bars", " ": "spaces"}


def _other_separator(line: str) -> str | None:
    """The name of the separator a one-column header line is split by, if any."""
    counts = {name: line.strip().count(s) for s, name in _SEPARATORS.items()}
    best = max(counts, key=counts.get)
    return best if counts[best] else None


def _isfloat(s):
    try:
        float(s)
        return True
    except ValueError:
        return False


def format_record(rec: Record) -> str:
    buf = io.StringIO()
    for k, v in rec.meta.items():
        buf.write(f"# {k}: {v}\n")
    cols = list(rec.order)
    buf.write(",".join(["t", *cols]) + "\n")
    data = np.column_stack([rec.t, *[rec[c] for c in cols]])
    np.savetxt(buf, data, delimiter=",", fmt="%.12g")
    return buf.getvalue()


def write_record(rec: Record, path, overwrite: bool = False, protect=()) -> Path:
    """Write ``rec`` (12 significant digits) atomically; never over ``protect``.

    Parameters
    ----------
    rec : Record
        The record.
    path : path-like
        The CSV file to write.
    overwrite : bool
        Replace an existing regular file (default: refuse).
    protect : iterable of path-like
        Files never written over (a command's inputs).
    """
    return safe_write_text(path, format_record(rec), overwrite, protect)


__all__ = ["REQUIRED_META", "INPUT_COLUMNS", "FLAP_COLUMNS", "CONTROL_COLUMNS", "JITTER",
           "DT_PLAUSIBLE", "BAND_ROUNDING", "MAX_SAMPLES", "band_needs", "Record",
           "TRIM_MARGIN", "MIN_TRIM_SAMPLES", "SHORT_TRIM", "Trim", "first_movement",
           "require_control_movement", "find_trim", "perturbations", "model_inputs",
           "header_meta", "read_record", "parse_record", "format_record", "write_record"]
