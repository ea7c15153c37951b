"""A virtual flight-test campaign: records from the nonlinear truth at several speeds.

At every advance ratio of ``mus`` (default 0.10 to 0.35 in steps of 0.05), every
input shape of ``shapes`` on every control of ``controls``, ``repeats`` times
with its own noise seed: one record each from the nonlinear individual-blade
truth (:func:`inflowsim.flighttest.nonlinear.nonlinear_flighttest`; its Pitt-Peters
time constants and the Eq. (14) coupling change with ``mu``, so what the
campaign estimates has a trend to find).  Written as CSV records with a CSV
manifest ``plan.csv`` (record, condition ``mu=0.100``, manoeuvre, group
``repeat N``) that ``inflowsim campaign`` reads.

The shapes are the doublet and the 3-2-1-1 of :mod:`inflowsim.data.inputs` and a
log frequency sweep (0.15-3 Hz, from 2 s to 1 s before the record's end, faded in
and out over 1 s; :func:`inflowsim.data.inputs.log_sweep`), the three inputs a
flight-test campaign flies on each control, each of 0.25 deg (:data:`AMPLITUDE_DEG`:
the truth's linear range at the default noise).  Records are generated in parallel by
a process pool (they pickle).
"""
from __future__ import annotations

from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..channels import CONTROLS
from ..data.inputs import SHAPES
from ..errors import InputError

#: The campaign's speeds [-]: 0.10 to 0.35.
MUS = tuple(round(0.10 + 0.05 * i, 2) for i in range(6))
#: Input unit [s] per pulse shape: a doublet of 0.4 s half-width, a 3-2-1-1 of 0.3 s units.
WIDTH = {"doublet": 0.4, "3211": 0.3}
#: The campaign's input shapes, in plan order.
CAMPAIGN_SHAPES = (*SHAPES, "sweep")
#: The sweep's frequency range [Hz].
SWEEP_HZ = (0.15, 3.0)
#: Every input's amplitude [deg] (the sweep's peak): the truth's linear range at the
#: default 1e-4 rad flap noise.  At 1 deg the joint fits' equivalent linear parameters
#: sit up to 3 of their bounds off the truth's (tau0 low, the flap frequency high); at
#: 0.25 deg under 2 on average at every speed, about what the estimator leaves on a
#: truth the catalogue holds exactly, with bounds three times wider
#: (``bench/amplitude.md``).
AMPLITUDE_DEG = 0.25


@dataclass(frozen=True)
class CampaignItem:
    """One record of the campaign: speed ``mu``, ``control``, input ``shape``,
    ``repeat`` (its noise seed is derived from all four)."""

    mu: float
    control: str
    shape: str
    repeat: int

    @property
    def name(self) -> str:
        return f"mu{self.mu:.3f}_{self.control}_{self.shape}_r{self.repeat}.csv"

    @property
    def condition(self) -> str:
        return f"mu={self.mu:.3f}"

    @property
    def manoeuvre(self) -> str:
        return f"{self.shape} {self.control}"

    @property
    def seed(self) -> int:
        return (int(round(self.mu * 1000)) * 1009 + CONTROLS.index(self.control) * 101
                + CAMPAIGN_SHAPES.index(self.shape) * 13 + self.repeat) % (2 ** 32)


def campaign_items(mus=MUS, controls=CONTROLS, shapes=CAMPAIGN_SHAPES, repeats=1):
    """Every record of the campaign, in plan order (speed, control, shape, repeat)."""
    for s in shapes:
        if s not in CAMPAIGN_SHAPES:
            raise InputError(f"input shape {s!r}: choose {', '.join(CAMPAIGN_SHAPES)}")
    for c in controls:
        if c not in CONTROLS:
            raise InputError(f"control {c!r}: choose {', '.join(CONTROLS)}")
    for m in mus:
        if not 0.05 <= m <= 0.45:
            raise InputError(f"mu {m:g}: the virtual campaign flies 0.05 <= mu <= 0.45")
    if repeats < 1:
        raise InputError(f"repeats {repeats}: need at least 1")
    return [CampaignItem(float(m), c, s, r) for m in mus for c in controls for s in shapes
            for r in range(repeats)]


def truth_label(speed: str = "eq14", n_blades: int = 4, body: bool = True) -> str:
    """What a campaign's records were flown with (their ``truth`` metadata): a
    restarted generation keeps only records of the same truth."""
    return (f"nonlinear blade-element, {n_blades} blades, speed {speed}, "
            f"{'body motion' if body else 'hub fixed'}")


def flown_label(duration: float = 20.0, dt: float = 1.0 / 64, noise: float = 1e-4,
                amplitude_deg: float = AMPLITUDE_DEG) -> str:
    """How a campaign's records were flown (their ``flown`` metadata): a restarted
    generation keeps only records flown alike, so one campaign never mixes input
    amplitudes, noise levels or record lengths."""
    return (f"{amplitude_deg:g} deg inputs, flap noise {noise:g} rad, {duration:g} s "
            f"at dt {dt:g} s")


def campaign_record(item: CampaignItem, duration=20.0, dt=1.0 / 64, noise=1e-4,
                    speed="eq14", n_blades=4, body=True, amplitude_deg=AMPLITUDE_DEG):
    """The record of one campaign item (the nonlinear truth at ``item.mu``, with the
    speed through the disc ``speed``, ``n_blades`` blades and, unless ``body`` is
    false, the body's motion; inputs of ``amplitude_deg`` [deg])."""
    from ..model.params import PUMA
    from .bladesim import RotorSpec
    from .nonlinear import FlightTest, nonlinear_flighttest
    from .virtual import Manoeuvre
    if item.shape == "sweep":
        man = Manoeuvre(channel=item.control, shape="sweep",
                        amplitude=np.radians(amplitude_deg),
                        t_start=2.0, f_range=SWEEP_HZ, length=max(duration - 3.0, 2.0))
    else:
        man = Manoeuvre(channel=item.control, shape=item.shape,
                        amplitude=np.radians(amplitude_deg),
                        t_start=2.0, width=WIDTH[item.shape])
    rotor = RotorSpec(constants=PUMA.with_mu(item.mu), speed=speed, n_blades=n_blades)
    test = FlightTest(rotor=rotor, manoeuvres=(man,), duration=duration, dt=dt,
                      noise_flap=noise, seed=item.seed,
                      body=FlightTest().body if body else None,
                      description=f"{item.manoeuvre} at mu {item.mu:g}, nonlinear "
                                  "blade-element truth")
    rec = nonlinear_flighttest(test).record
    return rec.with_meta(manoeuvre=item.manoeuvre, condition=item.condition,
                         truth=truth_label(speed, n_blades, body),
                         flown=flown_label(duration, dt, noise, amplitude_deg))


def _make(args):
    item, folder, duration, dt, noise, truth, amplitude_deg = args
    from ..data.record import write_record
    path = Path(folder) / item.name
    if path.exists():           # a restarted generation keeps what it has (same truth)
        return str(path), False
    write_record(campaign_record(item, duration, dt, noise, amplitude_deg=amplitude_deg,
                                 **truth), path)
    return str(path), True


def virtual_campaign(folder, mus=MUS, controls=CONTROLS, shapes=CAMPAIGN_SHAPES, repeats=1,
                     duration=20.0, dt=1.0 / 64, noise=1e-4, workers=None,
                     progress=None, speed="eq14", n_blades=4, body=True,
                     amplitude_deg=AMPLITUDE_DEG) -> Path:
    """Write the campaign's records and its plan ``folder/plan.csv``; returns the plan.

    Records already in ``folder`` (same name, same truth, flown alike) are kept, so
    an interrupted generation resumes; one of another truth (``speed``, ``n_blades``,
    ``body``: :func:`campaign_record`) or flown otherwise (``amplitude_deg``,
    ``noise``, ``duration``, ``dt``; or by a version that did not record how) is
    refused.  ``amplitude_deg`` [deg]: every
    input's amplitude (default :data:`AMPLITUDE_DEG`, the truth's linear range at the
    default ``noise``; 1 deg flies it outside: with the Eq. (14) speed the joint fits'
    ``tau0`` sits 2.4-3.0 bounds low at mu 0.10 and 0.35, ``bench/amplitude.md``).
    ``workers`` processes (default the machine's cores)."""
    import os

    from ..data.record import header_meta
    from ..fileio import check_folder, safe_write_text
    folder = check_folder(folder)
    folder.mkdir(exist_ok=True)
    from .bladesim import RotorSpec
    RotorSpec(speed=speed, n_blades=n_blades).check()   # one line here, not in a worker
    items = campaign_items(mus, controls, shapes, repeats)
    truth = {"speed": speed, "n_blades": int(n_blades), "body": bool(body)}
    label = truth_label(**truth)
    flown = flown_label(duration, dt, noise, amplitude_deg)
    for it in items:                           # before any work: one line, nothing made
        path = folder / it.name
        if path.exists() and not path.is_file():
            raise InputError(f"{path}: is not a regular file; the campaign writes its "
                             "record there: move it or use another folder")
        if path.exists():
            # records written before the truth was named were all of the default truth,
            # and say so in their description; any other record is another truth's
            meta = header_meta(path)
            desc = meta.get("description", "")
            kept = meta.get("truth") or (truth_label() if desc.endswith(
                "nonlinear blade-element truth") else f"not recorded: '{desc}'")
            if kept != label:
                raise InputError(f"{path}: a record of another truth ({kept}) is in "
                                 f"the folder, not one of '{label}': write this "
                                 "campaign to another folder")
            was = header_meta(path).get("flown")
            if was != flown:
                raise InputError(f"{path}: a record flown otherwise "
                                 f"({was or 'how is not recorded: an older inflowsim'}) "
                                 f"is in the folder, not '{flown}': fly the same "
                                 "settings or write this campaign to another folder")
    jobs = [(it, str(folder), duration, dt, noise, truth, float(amplitude_deg))
            for it in items]
    n = workers or os.cpu_count() or 1
    done = 0
    if n == 1:
        results = map(_make, jobs)
    else:
        ex = ProcessPoolExecutor(max_workers=n)
        results = ex.map(_make, jobs)
    try:
        for path, made in results:
            done += 1
            if progress:
                progress(f"flighttest campaign: {done}/{len(items)} {Path(path).name}"
                         f"{'' if made else ' (kept)'}")
    finally:
        if n != 1:
            ex.shutdown()
    plan = folder / "plan.csv"
    safe_write_text(plan, plan_text(items), overwrite=True)
    return plan


def plan_text(items) -> str:
    """The CSV manifest of ``items`` (``inflowsim.campaign.plan``): record names
    relative to the plan's folder."""
    import csv
    import io
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["record", "condition", "manoeuvre", "group"])
    for it in items:
        w.writerow([it.name, it.condition, it.manoeuvre, f"repeat {it.repeat}"])
    return buf.getvalue()


__all__ = ["MUS", "WIDTH", "CAMPAIGN_SHAPES", "SWEEP_HZ", "AMPLITUDE_DEG", "CampaignItem",
           "campaign_items", "truth_label", "flown_label", "campaign_record",
           "virtual_campaign", "plan_text"]
