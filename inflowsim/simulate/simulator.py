"""Fixed-step simulator fit for a simulator loop.

Conventions (the same in the FMU): inputs and outputs are perturbations about
trim in SI units, named as the record columns.  ``step(u)`` holds ``u`` over
``[t_k, t_k + dt)`` and returns the outputs at ``t_{k+1}``; :meth:`replay` returns
the outputs at every sample ``t_k`` with ``y[0]`` the initial output, the same
convention as ``scipy.signal.dlsim``.  Time is ``t0 + k dt`` from a step
counter, never a running sum (after :meth:`~Simulator.set_dt`, from the time of
the change).  Output delays are exact for held inputs: a delay of ``(m + f) dt``
reads the state a fraction ``1 - f`` into an earlier step.

A loop that follows the flight condition (:meth:`~Simulator.set_mu` every step)
takes the discrete matrices from a table in ``mu`` built once per parameter set
(with a parameter schedule, :mod:`inflowsim.model.schedule`, the scheduled
parameters at each ``mu`` are tabulated with it, so they cost nothing more a step),
and a step that changes (:meth:`~Simulator.set_dt`) from the Taylor series of the
solution: the FMU's table, its evaluation, Taylor step and term rule, one
description (:mod:`.algorithms`, :mod:`.mutable`).  Inputs are
refused with one line (:class:`~inflowsim.errors.InputError`) if they are not
real numbers, not finite or beyond ``U_MAX``; RK4 is refused at a step where it is
unstable (:func:`~inflowsim.simulate.discrete.rk4_max_step`).
"""
from __future__ import annotations

import numpy as np

from .discrete import TaylorZoh, discretize, lifted_replay, rk4_max_step
from .mutable import MU_HI, MU_LO, MuTable
from ..channels import LIMIT
from ..errors import InputError

#: Largest input magnitude a step takes (channels.LIMIT: the FMU declares the same).
U_MAX = LIMIT
_U_MAX2 = U_MAX * U_MAX


def checked_inputs(u, what: str, shape) -> np.ndarray:
    """``u`` as a float array of ``shape`` (``None``: any length), or
    :class:`InputError` starting with ``what`` and naming the trouble: not numbers
    (None, strings, complex numbers), the wrong shape, NaN or infinite values,
    magnitudes beyond ``U_MAX``."""
    if u is None:
        raise InputError(f"{what}, got None")
    try:
        a = np.asarray(u)
    except (TypeError, ValueError):
        raise InputError(f"{what}, got {type(u).__name__}") from None
    if a.dtype.kind == "c":
        raise InputError(f"{what}: got complex numbers (the inputs are real)")
    if a.dtype.kind in "USO" and a.ndim == 0:
        raise InputError(f"{what}, got {type(u).__name__}")
    if a.dtype.kind in "US" or (a.dtype.kind == "O" and any(
            isinstance(v, (str, bytes)) for v in a.ravel())):
        raise InputError(f"{what}: got text, not numbers")
    if a.dtype.kind == "O" and any(isinstance(v, complex) for v in a.ravel()):
        raise InputError(f"{what}: got complex numbers (the inputs are real)")
    try:
        a = a.astype(float)
    except (TypeError, ValueError):
        raise InputError(f"{what}, got {a.dtype} values that are not numbers") from None
    if a.ndim != len(shape) or any(w is not None and w != g for w, g in zip(shape, a.shape)):
        raise InputError(f"{what}, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise InputError(f"{what}: got a NaN or infinite value (inputs must be finite)")
    big = np.abs(a).max(initial=0.0)
    if big > U_MAX:
        raise InputError(f"{what}: |u| = {big:g} is beyond {U_MAX:g} (the FMU refuses "
                         "the same; inputs are SI perturbations about trim)")
    return a


def _checked_schedule(schedule, model):
    """``schedule`` if it can drive ``model``: a Schedule whose names are all the
    model's parameters; else :class:`InputError`."""
    from ..model.schedule import Schedule
    if not isinstance(schedule, Schedule):
        raise InputError("schedule: a Schedule is needed (inflowsim.model.schedule."
                         f"read_schedule(path) or fit_schedule(...)), not "
                         f"{type(schedule).__name__}")
    names = list(schedule.names) + [n for n, _, _ in schedule.held]
    alien = [n for n in names if n not in model.parameters]
    if alien:
        raise InputError(f"schedule: {', '.join(alien)} not among the parameters of the "
                         f"model {model.structure.name} (the schedule is for "
                         f"{schedule.structure})")
    return schedule


class Simulator:
    """Step a :class:`~inflowsim.model.Model` with a fixed step ``dt`` [s].

    Parameters
    ----------
    model : Model
    dt : float
        Step [s], > 0.
    method : {"zoh", "rk4"}
        Exact zero-order hold (default) or classical RK4 with held input.
    x0 : array_like, optional
        Initial state (perturbation), default zero.
    t0 : float
        Time of step 0 [s].
    schedule : Schedule, optional
        Parameters as functions of ``mu`` (:class:`~inflowsim.model.schedule.
        Schedule`, e.g. ``read_schedule(path)``): the model's parameters that it
        schedules or holds are replaced by its values at the ``mu`` of every step
        (at ``model.constants.mu`` from the start); the others stay the model's.
        A schedule with a trim (:attr:`~inflowsim.model.schedule.Schedule.trim`)
        sets ``Constants.trim`` at every step's ``mu`` likewise.
    """

    def __init__(self, model, dt: float, method: str = "zoh", x0=None, t0: float = 0.0,
                 schedule=None):
        if not (np.isfinite(dt) and dt > 0):
            raise InputError(f"dt = {dt}: the step must be a finite number > 0 s")
        if method not in ("zoh", "rk4"):
            raise InputError(f"method {method!r}: choose zoh or rk4")
        self.dt = float(dt)
        self.method = method
        self.t0 = float(t0)
        self._schedule = None
        if schedule is not None:
            self._schedule = _checked_schedule(schedule, model)
            model = self._scheduled(model, model.constants.mu)
        self._set_model(model)
        self.reset(x0)

    @property
    def schedule(self):
        """The parameter schedule followed (None: the parameters are constants)."""
        return self._schedule

    def _scheduled(self, model, mu):
        """``model`` at ``mu``, with the scheduled parameters there if there is a
        schedule."""
        if self._schedule is None:
            return model.with_mu(mu)
        from ..model.build import build_model
        p = dict(model.parameters)
        p.update(self._schedule(mu))
        # the trim too, where the schedule has one: effects linearised about the
        # trim take that of this mu
        return build_model(model.structure, p, self._schedule.constants_at(
            model.constants, mu))

    @property
    def model(self):
        """The model at the current flight condition (rebuilt when first asked for
        after a change of ``mu`` applied from the table)."""
        if self._model_mu is not None:
            self._model = self._scheduled(self._model, self._model_mu)
            self._model_mu = None
        return self._model

    # -- model and discretisation ---------------------------------------
    def _set_model(self, model):
        if np.any(model.delays < 0) or np.any(model.input_delays != 0):
            raise InputError(
                f"Simulator: the model {model.structure.name} has "
                + ("a lead on a flap output" if np.any(model.delays < 0)
                   else "time shifts on its inputs")
                + ", which a step-by-step loop cannot apply causally; replay a whole "
                  "record with inflowsim.simulate.replay.replay, or drop the time-shift effects "
                  "(they describe the recording, not the rotor)")
        a, b, c = model.a, model.b, model.c
        if self.method == "rk4":
            self._check_rk4(model)
        self._model, self._model_mu = model, None
        self._mu = model.constants.mu
        self._load_matrices = None          # built on the first loads() call
        self.n, self.m = b.shape
        phi, gam = discretize(a, b, self.dt, self.method)
        self._set_pg(np.hstack([phi, gam]), c)
        self._delay = self._delay_tables(model.delays)
        # the mu table: built at the second mu change under these parameters (one
        # change costs one exact rebuild, a loop that follows the flight condition
        # one table); None: not yet, False: not possible or not accurate enough
        self._mu_table = None
        self._mu_changes = 0
        self._taylor = None                 # set_dt's series, built at its first call

    def _set_pg(self, pg, c):
        # [x+; y+; check]: the last row sums [x; u], so a NaN or infinite state
        # shows in one number the step reads without another array operation.
        # phi and gam are views of it, so a table update moves them too.
        n = self.n
        self._M = np.vstack([pg, c @ pg, np.ones((1, pg.shape[1]))])
        self._Mtop = self._M[:-1].reshape(-1)   # what the mu table writes (a view)
        self.phi, self.gam = self._M[:n, :n], self._M[:n, n:]

    def _check_rk4(self, model):
        h = rk4_max_step(np.linalg.eigvals(model.a))
        if self.dt > h:
            raise InputError(
                f"dt = {self.dt:g} s: RK4 is unstable for model {model.structure.name} "
                f"at this step (its eigenvalues need dt <= {h:.4g} s, the largest stable "
                "step); use a smaller dt or method zoh (exact at any step)")

    def _delay_tables(self, delays):
        """Per distinct non-zero delay: whole steps, fraction and partial-step maps."""
        if not np.any(delays > 0):
            return None
        groups = []
        for d in np.unique(delays[delays > 0]):
            steps = d / self.dt
            mm = int(np.floor(steps + 1e-12))
            f = steps - mm
            if f < 1e-12:
                f = 0.0
            phf, gaf = (discretize(self.model.a, self.model.b, (1 - f) * self.dt, self.method)
                        if f > 0 else (None, None))
            groups.append((np.flatnonzero(delays == d), mm, f, phf, gaf))
        depth = max(g[1] for g in groups) + 2
        return groups, depth

    def set_model(self, model):
        """Swap in another model of the same structure, keeping the state (with a
        schedule, its scheduled parameters at the model's ``mu``)."""
        if self._schedule is not None:
            _checked_schedule(self._schedule, model)
            model = self._scheduled(model, model.constants.mu)
        self._replace_model(model)

    def _replace_model(self, model):
        if model.b.shape != (self.n, self.m):
            raise InputError("set_model: the new model has other states or inputs")
        x = self.state
        hist = getattr(self, "_hist", None)
        self._set_model(model)
        self._xu[: self.n] = x
        if self._delay is not None and hist is not None and len(hist[0]) == self._delay[1]:
            self._hist = hist
        elif self._delay is not None:
            self._init_hist(x)

    def set_mu(self, mu: float):
        """Change the flight condition between steps; the discrete matrices follow.

        The first change rebuilds the model exactly; from the second under the same
        parameters and step, the discrete matrices come from a table in ``mu``
        built once (:mod:`inflowsim.simulate.mutable`, the FMU's table; within
        1e-12 of the exact zero-order hold) and the model itself is rebuilt only
        when :attr:`model` is read.  Exact rebuilds every time for RK4, output
        delays and ``mu`` outside the table's ``[0.1, 0.5]`` (the mass-flow speed on
        its way to hover)."""
        if mu == self._mu:
            return
        t = self._mu_table
        if t and MU_LO <= mu <= MU_HI:
            t.into(mu, self._Mtop)
            self._mu = mu
            self._model_mu = mu
            self._load_matrices = None
            return
        if t is None:
            self._mu_changes += 1
            if self._mu_changes >= 2:
                self._mu_table = t = self._build_mu_table()
                if t:
                    self.set_mu(mu)
                    return
        model = self._scheduled(self.model, mu)
        changes, table = self._mu_changes, self._mu_table
        self._replace_model(model)
        self._mu_changes, self._mu_table = changes, table

    def _build_mu_table(self):
        """The table of ``[phi gam; c phi, c gam]`` in ``mu``, or False where there is
        none (see :meth:`set_mu`) or its check failed."""
        model = self.model
        if self.method != "zoh" or self._delay is not None:
            return False
        sched = self._schedule

        def exact(mu):
            m = self._scheduled(model, mu)
            pg = np.hstack(discretize(m.a, m.b, self.dt))
            return np.vstack([pg, m.c @ pg])      # c too: an azimuth bias may follow mu

        t = MuTable(exact, (slice(0, self.n), slice(self.n, None)),
                    knots=sched.knots(MU_LO, MU_HI) if sched is not None else ())
        return t if t.ok else False

    def set_dt(self, dt: float):
        """Change the step [s] between steps, keeping the state and the step count
        (:attr:`time` goes on from the time of the change in steps of the new dt; a
        model with output delays restarts its delay line).

        The zero-order hold at the new step is the FMU's Taylor step with its
        term rule (:class:`~inflowsim.simulate.discrete.TaylorZoh`), or the matrix
        exponential where that needs too many terms."""
        if not (np.isfinite(dt) and dt > 0):
            raise InputError(f"dt = {dt}: the step must be a finite number > 0 s")
        dt = float(dt)
        if dt == self.dt:
            return
        model = self.model
        self._tb, self._kb = self.time, self._k
        old = self.dt
        self.dt = dt
        if self.method == "rk4":
            try:
                self._check_rk4(model)
            except InputError:
                self.dt = old
                raise
        if self._delay is not None:
            x = self.state
            self._set_model(model)
            self._xu[: self.n] = x
            self._init_hist(x)
            return
        self._mu_table, self._mu_changes = None, 0
        if self.method == "zoh":
            if self._taylor is None or self._taylor.a is not model.a:
                self._taylor = TaylorZoh(model.a, model.b)
            pg = self._taylor.pg(dt)
            if pg is not None:
                self._set_pg(pg, model.c)
                return
        self._set_pg(np.hstack(discretize(model.a, model.b, dt, self.method)), model.c)

    # -- state ------------------------------------------------------------
    def reset(self, x0=None):
        """Back to step 0 with state ``x0`` (default zero)."""
        self._k = 0
        self._tb, self._kb = self.t0, 0      # time = _tb + (k - _kb) dt (set_dt moves it)
        self._xu = np.zeros(self.n + self.m)
        self._uview = self._xu[self.n:]     # the inputs' part, for the step's check
        if x0 is not None:
            self.state = x0
        if self._delay is not None:
            self._init_hist(self.state)

    def _init_hist(self, x):
        depth = self._delay[1]
        self._hist = (np.tile(x, (depth, 1)), np.zeros((depth, self.m)),
                      np.full(depth, -1, dtype=np.int64))

    @property
    def state(self) -> np.ndarray:
        return self._xu[: self.n].copy()

    @state.setter
    def state(self, x):
        x = np.asarray(x, dtype=float)
        if x.shape != (self.n,) or not np.all(np.isfinite(x)):
            raise InputError(f"state must be {self.n} finite numbers "
                             f"({', '.join(self.model.states)})")
        self._xu[: self.n] = x

    @property
    def step_count(self) -> int:
        return self._k

    @property
    def time(self) -> float:
        return self._tb + (self._k - self._kb) * self.dt

    def outputs(self) -> np.ndarray:
        """Outputs at the current time (undelayed channels exact; delayed ones use
        the stored history)."""
        y = self.model.c @ self.state
        if self._delay is not None:
            y = self._apply_delays(y, self._k)
        return y

    def loads(self) -> np.ndarray:
        """Rotor load coefficients now: ``CT, C_mc, C_ms`` (Eq. (4)) and the flap
        springs' hub moments ``C_mc_hub, C_ms_hub`` [-], perturbations about trim
        (:mod:`inflowsim.model.loads`; ``dimensional_loads`` turns them into newtons
        and newton-metres).  From the current state and the input held over the last
        step (zero before the first; after a refused step, the refused input, so NaN
        until the next step)."""
        lm = self._load_matrices
        if lm is None:
            from ..model.loads import load_matrices
            lm = self._load_matrices = load_matrices(self.model)
        xu = self._xu
        return lm.c @ xu[: self.n] + lm.d @ xu[self.n:]

    # -- stepping -----------------------------------------------------------
    def step(self, u) -> np.ndarray:
        """Hold ``u`` (``model.inputs`` order, SI perturbations, each within
        ``U_MAX`` = 1e6 as in the FMU) over one step; return the six outputs at the
        new time.  Refused inputs (:class:`InputError`) leave the state unchanged."""
        xu = self._xu
        n = self.n
        # The cheapest exact checks found (bench/simulator.md): an array's dtype kind
        # (strings, complex numbers and None make another) and its sum of squares (at
        # most U_MAX^2, then every |u_i| <= U_MAX; NaN fails the comparison); a
        # list's max and min in Python, which raise TypeError on text, complex
        # numbers and None (a NaN they may pass shows in the check row below).
        # len() refuses scalars, and with it the assignment every other shape (a
        # length-1 or 1 x m array would broadcast).  Anything else, or any doubt:
        # the full check, which raises saying what is wrong or returns the numbers.
        try:
            cls = u.__class__
            if cls is np.ndarray:
                if u.dtype.kind not in "fiub" or len(u) != self.m:
                    raise ValueError
                xu[n:] = u
                uv = self._uview
                if not uv.dot(uv) <= _U_MAX2:
                    raise ValueError
            elif cls is list or cls is tuple:
                if len(u) != self.m or not (max(u) <= U_MAX and min(u) >= -U_MAX):
                    raise ValueError
                xu[n:] = u
            else:
                raise ValueError
        except (TypeError, ValueError):
            xu[n:] = self._inputs(u)
        # ndarray.dot: about half the call overhead of @ for this small matrix-vector
        # product (bench/simulator.md), which more than pays for the checks
        out = self._M.dot(xu)
        check = out.item(-1)
        if check - check != 0.0:            # NaN or infinite (0 * NaN is NaN)
            self._inputs(u)                 # a NaN input: says so
            raise InputError("step: the state is not finite (the model grew without "
                             "bound); the state is unchanged")
        if self._delay is not None:
            self._push(xu[:n].copy(), xu[n:].copy())
        xu[:n] = out[:n]
        self._k += 1
        y = out[n:-1]
        if self._delay is not None:
            y = self._apply_delays(y, self._k)
        return y

    def _inputs(self, u) -> np.ndarray:
        """``u`` as ``m`` finite real numbers within ``U_MAX``, or one line saying
        what is wrong with it."""
        names = ", ".join(self.model.inputs)
        return checked_inputs(u, f"step: inputs must be {self.m} numbers ({names})",
                              (self.m,))

    def _push(self, x, u):
        hx, hu, hk = self._hist
        slot = self._k % len(hk)
        hx[slot], hu[slot], hk[slot] = x, u, self._k

    def _apply_delays(self, y, k):
        hx, hu, hk = self._hist
        depth = len(hk)
        c = self.model.c
        y = y.copy()
        for rows, mm, f, phf, gaf in self._delay[0]:
            if f == 0.0:
                j = k - mm
                if j == k:
                    continue
                x = self._hist_state(j)
            else:
                j = k - mm - 1
                if j < 0 or hk[j % depth] != j:
                    x = self._x0_hist()
                else:
                    x = phf @ hx[j % depth] + gaf @ hu[j % depth]
            y[rows] = c[rows] @ x
        return y

    def _hist_state(self, j):
        hx, hu, hk = self._hist
        if j <= 0:
            return self._x0_hist()
        prev = j - 1
        slot = prev % len(hk)
        if hk[slot] != prev:
            return self._x0_hist()
        return self.phi @ hx[slot] + self.gam @ hu[slot]

    def _x0_hist(self):
        hx, _, hk = self._hist
        i = np.flatnonzero(hk == 0)
        return hx[i[0]] if i.size else self.state

    # -- batch ----------------------------------------------------------------
    def replay(self, u, x0=None) -> np.ndarray:
        """Outputs at every sample for an input sequence ``u`` of shape ``(N, m)``.

        Does not touch the stepping state.  ``y[k]`` is the output at ``t_k``
        (``y[0]`` from ``x0``), identical to ``dlsim`` on ``(phi, gam, c, 0)``.
        Delayed channels before ``t0 + delay`` hold the initial output.
        """
        u = checked_inputs(u, f"replay needs inputs of shape (N, {self.m}) "
                           f"({', '.join(self.model.inputs)})", (None, self.m))
        x0 = np.zeros(self.n) if x0 is None else np.asarray(x0, dtype=float)
        xs = lifted_replay(self.phi, self.gam, u, x0)
        c = self.model.c
        # einsum's own loop: a tall-skinny BLAS product can cost 100x more when
        # multithreaded BLAS competes for a loaded machine's cores.
        y = np.einsum("kn,on->ko", xs, c)
        if self._delay is not None:
            for rows, mm, f, phf, gaf in self._delay[0]:
                if f == 0.0:
                    xd = np.vstack([np.tile(x0, (mm, 1)), xs])[: len(xs)]
                else:
                    xf = (np.einsum("kn,on->ko", xs, phf)
                          + np.einsum("km,om->ko", u, gaf))   # state at t_j + (1-f) dt
                    xd = np.vstack([np.tile(x0, (mm + 1, 1)), xf])[: len(xs)]
                y[:, rows] = np.einsum("kn,on->ko", xd, c[rows])
        return y

    def states(self, u, x0=None) -> np.ndarray:
        """States at every sample for inputs ``u`` (``(N, n)``)."""
        x0 = np.zeros(self.n) if x0 is None else np.asarray(x0, dtype=float)
        return lifted_replay(self.phi, self.gam, np.asarray(u, dtype=float), x0)


__all__ = ["U_MAX", "checked_inputs", "Simulator"]
