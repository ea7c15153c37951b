"""NASA laser-velocimeter inflow surveys (Elliott et al. 1988, Hoad et al. 1989).

Reads the tables of ``inflowsim/data/nasa_lv_inflow/`` (shipped with the package: NASA
public data, source and licence named there) as they are (never edits them):
time-averaged induced inflow over the tip speed at stations ``(psi, r/R)`` above a
four-bladed model rotor at ``mu`` 0.15, 0.23 and 0.35, and the run conditions of the
folder's ``README.md``.  Every defect the reader finds is returned as a
:class:`Defect` saying what was seen, how it was detected and what was done: nothing
is dropped or changed silently.

Conventions of the returned :class:`Survey` (``model.md`` section 1): azimuth
``psi`` [rad], 0 aft, increasing with rotation (the tables' own convention);
``lambda_i`` the induced inflow over ``Omega R``, **down positive** (the tables'
sign reversed: they give negative numbers for downwash); cyclic pitch in the model's
``theta = theta0 + theta1c cos psi + theta1s sin psi``.  The tables' cyclic columns
are the classical ``A1, B1`` of ``theta0 - A1 cos psi - B1 sin psi`` (forward flight
needs less pitch on the advancing side, ``psi = 90 deg``; the tabulated ``B1`` is
positive and grows with ``mu``, 3.23 / 4.13 / 6.80 deg), so ``theta1c = -A1`` and
``theta1s = -B1``.
"""
from __future__ import annotations

import csv
import hashlib
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InputError

#: Column names as the three files spell them (case-insensitive), by quantity.
HEADER_ALIASES = {"psi": ("psi",), "r": ("r/r",), "mean": ("mean", "lam mean"),
                  "std": ("std", "lam std"), "count": ("num_measure",)}
#: A tabulated standard deviation this many times the file's median is not a
#: sample scatter of this rig (transcription: see ``_std_defects``).
STD_OUTLIER_FACTOR = 10.0
#: Eq. (6) is the inflow over the disc: stations beyond the tip are read, not fitted.
DISC_EDGE = 1.0
_WORDS = {"two": 2, "three": 3, "four": 4, "five": 5, "six": 6}
_FILE = re.compile(r"^mu_(\d+)\.csv$")


@dataclass(frozen=True)
class Defect:
    """One defect of a table, as found.

    ``kind`` one of ``duplicate-azimuth``, ``std-transcription``, ``radial-station``,
    ``extra-decimals``, ``outside-disc``, ``extra-column``, ``missing-points``,
    ``checksum``; ``lines`` the file lines concerned (1 = header); ``detail`` what
    was seen and how it was detected; ``action`` what the reader did about it.
    """

    file: str
    kind: str
    lines: tuple[int, ...]
    detail: str
    action: str

    def __str__(self):
        where = f" (lines {', '.join(map(str, self.lines))})" if self.lines else ""
        return f"{self.file}: {self.kind}{where}: {self.detail}; {self.action}"


@dataclass(frozen=True)
class RunConditions:
    """Rotor and run conditions of one survey (the folder README's tables), SI units.

    ``speed`` tunnel speed [m/s]; ``shaft_angle`` [rad], negative tilted forward;
    ``theta0`` collective at 0.75 R [rad]; ``theta1c``, ``theta1s`` cyclic pitch in
    the model's convention [rad] (the tables' ``-A1``, ``-B1``, see the module
    docstring); ``lag0`` mean lag as tabulated [rad]; ``twist`` root-to-tip linear
    twist [rad], zero at ``twist_zero_r``; ``omega`` [rad/s].
    """

    case: int
    mu_nominal: float
    ct: float
    speed: float
    shaft_angle: float
    theta0: float
    theta1c: float
    theta1s: float
    lag0: float
    blades: int
    radius: float
    chord: float
    omega: float
    twist: float
    twist_zero_r: float

    @property
    def tip_speed(self) -> float:
        """``Omega R`` [m/s]."""
        return self.omega * self.radius

    @property
    def mu(self) -> float:
        """In-plane advance ratio ``V cos(alpha_s) / (Omega R)`` [-]."""
        return self.speed * math.cos(self.shaft_angle) / self.tip_speed

    @property
    def muz(self) -> float:
        """Hub velocity normal to the disc over ``Omega R``, down positive
        (``model.md`` section 1): ``V sin(alpha_s) / (Omega R)``; negative for a shaft
        tilted forward, the free stream then passing down through the disc [-]."""
        return self.speed * math.sin(self.shaft_angle) / self.tip_speed

    @property
    def solidity(self) -> float:
        """``N c / (pi R)`` [-]."""
        return self.blades * self.chord / (math.pi * self.radius)

    def constants(self, a0: float):
        """The project's :class:`~inflowsim.model.params.Constants` of this run (the
        known pitch and ``muz`` as trim; the flap is not in the tables).

        ``a0`` the blade lift-curve slope [1/rad]: not in the data, the caller's
        choice (the comparison of ``inflow_survey`` does not need it)."""
        from ..model.params import Constants
        return Constants(mu=self.mu, a0=float(a0), solidity=self.solidity, omega=self.omega,
                         radius=self.radius, ct=self.ct,
                         trim={"theta0": self.theta0, "theta1c": self.theta1c,
                               "theta1s": self.theta1s, "muz": self.muz}).check()


@dataclass(frozen=True, eq=False)
class Survey:
    """One inflow survey as read, with what the reader found.

    Arrays are per row of the file (header excluded), in file order: ``line`` the
    file line [-]; ``psi`` azimuth [rad] (360 deg kept as read, ``2 pi``); ``r``
    radial station ``r/R`` [-] (repaired where a :class:`Defect` says so);
    ``lambda_i`` induced inflow over ``Omega R``, down positive [-]; ``sigma`` the
    tabulated standard deviation over the samples [-] (repaired where a defect says
    so); ``n_samples`` the number of samples (``mu_015.csv`` only, else None);
    ``in_fit`` the rows Eq. (6) is fitted to (on the disc, ``psi < 360 deg``, not
    excluded by a defect).
    """

    file: str
    sha256: str
    conditions: RunConditions
    line: np.ndarray
    psi: np.ndarray
    r: np.ndarray
    lambda_i: np.ndarray
    sigma: np.ndarray
    in_fit: np.ndarray
    n_samples: np.ndarray | None = None
    defects: tuple[Defect, ...] = field(default=())

    @property
    def mu(self) -> float:
        return self.conditions.mu

    def defects_of(self, kind: str) -> tuple[Defect, ...]:
        return tuple(d for d in self.defects if d.kind == kind)


def sha256_of(path) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def _decimals(text: str) -> int:
    return len(text.split(".")[1]) if "." in text else 0


def _drop_spurious_two(text: str) -> str | None:
    """``0.2xyz`` read as ``0.xyz``: the one transcription slip of these tables (a
    ``2`` inserted after the point).  None where the text is not of that form."""
    m = re.fullmatch(r"(-?)0\.2(\d+)", text.strip())
    if not m:
        return None
    digits = m.group(2)
    return f"{m.group(1)}0.{digits}"


def read_conditions(folder) -> dict[float, RunConditions]:
    """The run conditions of the folder's ``README.md`` by nominal ``mu``.

    Parses the rotor sentence (blades, radius, chord, twist, rpm) and the table of
    cases; one-line :class:`InputError` if the README is missing or not of that form.
    """
    path = Path(folder) / "README.md"
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise InputError(f"{path}: cannot read the run conditions ({exc.strerror})") from None

    def grab(pattern, what):
        m = re.search(pattern, text, flags=re.IGNORECASE)
        if not m:
            raise InputError(f"{path}: no {what} in the rotor description")
        return m.group(1)

    words = grab(r"(\w+)\s+blades,\s+radius", "blade count").lower()
    blades = int(words) if words.isdigit() else _WORDS.get(words)
    if blades is None:
        raise InputError(f"{path}: blade count {words!r} not understood")
    radius = float(grab(r"radius\s+([\d.]+)\s+m", "radius"))
    chord = float(grab(r"chord\s+([\d.]+)\s+m", "chord"))
    rpm = float(grab(r"([\d.]+)\s+rpm", "rotor speed (rpm)"))
    twist = math.radians(float(grab(r"twist\s+of\s+(-?[\d.]+)\s+deg", "twist")))
    twist_zero = float(grab(r"zero\s+twist\s+at\s+r/R\s*=\s*([\d.]+)", "twist reference station"))
    omega = rpm * math.pi / 30.0

    out = {}
    header = None
    for row in text.splitlines():
        cells = [c.strip() for c in row.strip().strip("|").split("|")]
        if "C_T" in cells and "mu" in cells:
            header = cells
            continue
        if header is None or len(cells) != len(header) or not cells[0].isdigit():
            continue
        try:
            v = dict(zip(header, (float(c) for c in cells)))
        except ValueError:
            raise InputError(f"{path}: run-conditions row {row.strip()!r} is not numbers") from None
        theta = [k for k in header if k.startswith("theta0")]
        lag = [k for k in header if k.startswith("mean lag")]
        alpha = [k for k in header if k.startswith("alpha")]
        if not (theta and lag and alpha and "theta1c (deg)" in v and "V (m/s)" in v):
            raise InputError(f"{path}: run-conditions table lacks a column "
                             "(need mu, C_T, V, alpha, theta0, theta1c, theta1s, mean lag)")
        out[round(v["mu"], 4)] = RunConditions(
            case=int(v["case"]), mu_nominal=v["mu"], ct=v["C_T"], speed=v["V (m/s)"],
            shaft_angle=math.radians(v[alpha[0]]), theta0=math.radians(v[theta[0]]),
            theta1c=-math.radians(v["theta1c (deg)"]),
            theta1s=-math.radians(v["theta1s (deg)"]), lag0=math.radians(v[lag[0]]),
            blades=blades, radius=radius, chord=chord, omega=omega, twist=twist,
            twist_zero_r=twist_zero)
    if not out:
        raise InputError(f"{path}: no run-conditions table (a row with mu and C_T)")
    return out


def _readme_checksums(folder) -> dict[str, str]:
    text = (Path(folder) / "README.md").read_text(encoding="utf-8")
    return dict(re.findall(r"`([\w.]+\.csv)`\s*\|\s*`([0-9a-f]{64})`", text))


def _columns(header, file):
    cols = {}
    for i, h in enumerate(header):
        key = next((k for k, names in HEADER_ALIASES.items() if h.strip().lower() in names),
                   None)
        if key is None:
            raise InputError(f"{file}: column {h!r} not understood (expected psi, r/R, "
                             "mean, std and optionally num_measure)")
        cols[key] = i
    missing = [k for k in ("psi", "r", "mean", "std") if k not in cols]
    if missing:
        raise InputError(f"{file}: missing column(s) {', '.join(missing)}")
    return cols


def read_survey(path, conditions: RunConditions | None = None,
                checksums: dict | None = None) -> Survey:
    """Read one table (``mu_*.csv``) as it is, detect and report its defects.

    Parameters
    ----------
    path : path-like
        The CSV file; never modified.
    conditions : RunConditions, optional
        Default: from the ``README.md`` beside it, by the ``mu`` in the file name.
    checksums : dict, optional
        ``{file name: sha256}`` to check against; default the README's table.

    Returns
    -------
    Survey
    """
    path = Path(path)
    folder = path.parent
    m = _FILE.match(path.name)
    if conditions is None:
        if not m:
            raise InputError(f"{path}: not a survey file name mu_<digits>.csv")
        mu_nom = float("0." + m.group(1).lstrip("0"))
        table = read_conditions(folder)
        if round(mu_nom, 4) not in table:
            raise InputError(f"{path}: no run conditions for mu = {mu_nom:g} in the README")
        conditions = table[round(mu_nom, 4)]
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise InputError(f"{path}: cannot read ({exc.strerror})") from None
    digest = hashlib.sha256(raw).hexdigest()
    try:
        rows = list(csv.reader(raw.decode("utf-8").splitlines()))
    except UnicodeDecodeError:
        raise InputError(f"{path}: not a UTF-8 text table") from None
    # blank lines carry nothing; the others keep their file line numbers
    numbered = [(i + 1, row) for i, row in enumerate(rows) if any(c.strip() for c in row)]
    if len(numbered) < 2:
        raise InputError(f"{path}: no data rows")
    cols = _columns(numbered[0][1], path.name)
    body = [row for _, row in numbered[1:]]
    lines = np.array([i for i, _ in numbered[1:]])
    defects: list[Defect] = []
    name = path.name

    if checksums is None:
        try:
            checksums = _readme_checksums(folder)
        except OSError:
            checksums = {}
    if name in checksums and checksums[name] != digest:
        defects.append(Defect(name, "checksum", (), f"sha256 {digest} differs from the "
                              f"README's {checksums[name]}", "read as it is"))

    def column(key):
        try:
            return [r[cols[key]].strip() for r in body]
        except IndexError:
            raise InputError(f"{path}: a row has fewer than {len(numbered[0][1])} "
                             "fields") from None

    txt = {k: column(k) for k in cols}
    try:
        num = {k: np.array([float(x) for x in v]) for k, v in txt.items()}
    except ValueError as exc:
        raise InputError(f"{path}: not a number ({exc})") from None
    psi_deg, r, mean, std = num["psi"], num["r"].copy(), num["mean"], num["std"].copy()
    in_fit = np.ones(len(body), dtype=bool)

    if "count" in cols:
        defects.append(Defect(name, "extra-column", (1,), f"column {rows[0][cols['count']]!r} "
                              "(number of samples) that the other tables lack",
                              "kept as Survey.n_samples; not used in the fit"))

    # psi = 360 is psi = 0 again: same stations, same means (the README says so;
    # checked here value by value)
    dup = np.isclose(psi_deg % 360.0, 0.0) & (psi_deg >= 360.0)
    if dup.any():
        zero = {round(rr, 4): i for i, rr in enumerate(r) if psi_deg[i] == 0.0}
        same_mean = all(round(r[i], 4) in zero and mean[zero[round(r[i], 4)]] == mean[i]
                        for i in np.where(dup)[0])
        std_differs = [int(lines[i]) for i in np.where(dup)[0] if round(r[i], 4) in zero
                       and std[zero[round(r[i], 4)]] != std[i]]
        detail = (f"{dup.sum()} rows at psi = 360 deg repeat psi = 0 "
                  f"({'every station and mean equal' if same_mean else 'NOT all means equal'}"
                  + (f"; standard deviations differ on lines {std_differs}" if std_differs
                     else "") + ")")
        defects.append(Defect(name, "duplicate-azimuth", tuple(int(x) for x in lines[dup]),
                              detail, "kept in the survey; left out of the fit (counted "
                              "once, at psi = 0) and used to cross-check the psi = 0 rows"))
        in_fit &= ~dup

    std_found = _std_defects(name, lines, psi_deg, r, std, txt["std"], dup, in_fit)
    defects += std_found
    defects += _station_defects(name, lines, psi_deg, r, txt["r"], in_fit)
    defects += _decimal_defects(name, lines, txt, {d.lines[0] for d in std_found})

    out = r > DISC_EDGE + 1e-9
    if out.any():
        defects.append(Defect(name, "outside-disc", tuple(int(x) for x in lines[out]),
                              f"{out.sum()} stations at r/R = "
                              f"{', '.join(f'{x:g}' for x in sorted(set(r[out])))} beyond the "
                              "tip", "kept in the survey; not fitted (Eq. (6) is the inflow "
                              "over the disc)"))
        in_fit &= ~out
    defects += _missing_points(name, psi_deg, r, dup)

    return Survey(file=name, sha256=digest, conditions=conditions, line=lines,
                  psi=np.radians(psi_deg), r=r, lambda_i=-mean, sigma=std, in_fit=in_fit,
                  n_samples=num["count"].astype(int) if "count" in num else None,
                  defects=tuple(defects))


def _std_defects(name, lines, psi_deg, r, std, text, dup, in_fit):
    """Standard deviations far above the file's median (``STD_OUTLIER_FACTOR``).

    Repaired by deleting the ``2`` after the point where the result is of the file's
    scale; where the psi = 360 duplicate of the same station exists, its value is
    quoted (it agrees on every station the survey repeats).  Otherwise the row is
    left out of the fit.
    """
    out = []
    med = float(np.median(std))
    for i in np.where(std > STD_OUTLIER_FACTOR * med)[0]:
        fixed = _drop_spurious_two(text[i])
        twin = [j for j in np.where(dup)[0] if psi_deg[i] == 0.0 and r[j] == r[i]]
        check = (f"; the psi = 360 row of this station reads {std[twin[0]]:g}" if twin
                 else "; no duplicate row to check against")
        what = (f"std {text[i]} at psi {psi_deg[i]:g} deg, r/R {r[i]:g} is "
                f"{std[i] / med:.0f} times the file's median {med:.4f} (detected: > "
                f"{STD_OUTLIER_FACTOR:g} x median)")
        if fixed is not None and float(fixed) < STD_OUTLIER_FACTOR * med:
            std[i] = float(fixed)
            out.append(Defect(name, "std-transcription", (int(lines[i]),), what + check,
                              f"repaired to {fixed} (a 2 inserted after the point)"))
        else:
            in_fit[i] = False
            out.append(Defect(name, "std-transcription", (int(lines[i]),), what + check,
                              "no repair of known form: left out of the fit"))
    return out


def _station_defects(name, lines, psi_deg, r, text, in_fit):
    """Radial stations off the survey's station grid (the stations most azimuths
    have) that break the ascending order of their radial cut.  Repaired by deleting
    the ``2`` after the point where that gives a grid station missing from the cut;
    otherwise left out of the fit."""
    out = []
    az = np.unique(psi_deg)
    counts = {}
    for x in r:
        counts[round(x, 4)] = counts.get(round(x, 4), 0) + 1
    grid = {x for x, n in counts.items() if n >= len(az) / 2}
    for p in az:
        idx = np.where(psi_deg == p)[0]
        for k, i in enumerate(idx):
            if round(r[i], 4) in grid:
                continue
            prev = r[idx[k - 1]] if k else -np.inf
            order = "breaks the ascending order of its cut" if r[i] < prev else "in order"
            fixed = _drop_spurious_two(text[i])
            have = {round(r[j], 4) for j in idx}
            what = (f"r/R {text[i]} at psi {p:g} deg is not a station of this survey "
                    f"(detected: off the grid of stations most azimuths share) and {order}")
            if fixed is not None and round(float(fixed), 4) in grid - have:
                r[i] = float(fixed)
                out.append(Defect(name, "radial-station", (int(lines[i]),), what,
                                  f"repaired to {float(fixed):g} (a 2 inserted after the "
                                  "point; that station is otherwise missing from the cut)"))
            else:
                in_fit[i] = False
                out.append(Defect(name, "radial-station", (int(lines[i]),), what,
                                  "no repair of known form: left out of the fit"))
    return out


def _decimal_defects(name, lines, txt, already=()):
    """Numbers written with more decimals than the column's usual count (the
    tables are rounded to a fixed number of decimals per column); rows in
    ``already`` (an earlier defect explains the digits) are not reported twice."""
    out = []
    for key in ("mean", "std"):
        dec = np.array([_decimals(x) for x in txt[key]])
        usual = int(np.bincount(dec).argmax())
        for i in np.where(dec > usual)[0]:
            if int(lines[i]) in already:
                continue
            x = float(txt[key][i])
            rounded = round(x, usual)
            out.append(Defect(name, "extra-decimals", (int(lines[i]),),
                              f"{key} {txt[key][i]} has {dec[i]} decimals where the column "
                              f"is given to {usual} (detected: decimals counted per value)",
                              f"kept as read: its {usual}-decimal rounding {rounded:g} "
                              f"differs by {abs(x - rounded):.1g}, "
                              f"{abs(x - rounded) / 10.0 ** -usual:.1g} of the table's last "
                              "digit"))
    return out


def _missing_points(name, psi_deg, r, dup):
    """Stations of the full grid (every 30 deg x every station of the survey) absent."""
    keep = ~dup
    stations = sorted(set(np.round(r[keep], 4)))
    have = {(round(p, 4), round(x, 4)) for p, x in zip(psi_deg[keep], r[keep])}
    miss_az, miss_pt = [], []
    for p in np.arange(0.0, 360.0, 30.0):
        absent = [x for x in stations if (round(p, 4), x) not in have]
        if len(absent) == len(stations):
            miss_az.append(f"{p:g}")
        else:
            miss_pt += [f"({p:g}, {x:g})" for x in absent]
    if not (miss_az or miss_pt):
        return []
    parts = []
    if miss_az:
        parts.append(f"no radial cut at psi = {', '.join(miss_az)} deg")
    if miss_pt:
        parts.append(f"{len(miss_pt)} stations (psi deg, r/R) absent: {' '.join(miss_pt)}")
    return [Defect(name, "missing-points", (), "; ".join(parts) + " (detected: against "
                   "every 30 deg x every station the survey has)", "nothing to repair: the "
                   "fit uses the points there are; its covariance carries the uneven "
                   "coverage")]


#: The surveys as the package ships them (NASA public data; the tables' source and
#: licence in the folder's ``README.md`` and ``LICENSE-BladeAD.txt``).
DATA_DIR = Path(__file__).resolve().parent / "nasa_lv_inflow"


def read_surveys(folder=None) -> tuple[Survey, ...]:
    """Every ``mu_*.csv`` of ``folder`` with its run conditions, by ascending ``mu``.

    Parameters
    ----------
    folder : path-like, optional
        The surveys' folder (its ``README.md`` gives the run conditions); default
        :data:`DATA_DIR`, the copy the package ships.

    One-line :class:`InputError` if the folder or its README is missing.
    """
    folder = Path(DATA_DIR if folder is None else folder)
    if not folder.is_dir():
        raise InputError(f"{folder}: no such data folder (the NASA inflow surveys; the "
                         f"package ships them in {DATA_DIR})")
    table = read_conditions(folder)
    sums = _readme_checksums(folder)
    files = sorted(p for p in folder.iterdir() if _FILE.match(p.name))
    if not files:
        raise InputError(f"{folder}: no survey files mu_<digits>.csv")
    out = []
    for p in files:
        mu_nom = float("0." + _FILE.match(p.name).group(1).lstrip("0"))
        if round(mu_nom, 4) not in table:
            raise InputError(f"{p}: no run conditions for mu = {mu_nom:g} in the README")
        out.append(read_survey(p, table[round(mu_nom, 4)], sums))
    return tuple(sorted(out, key=lambda s: s.conditions.mu_nominal))


__all__ = ["DATA_DIR", "Defect", "RunConditions", "Survey", "read_conditions",
           "read_survey", "read_surveys", "sha256_of"]
