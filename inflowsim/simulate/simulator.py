"""Fixed-step simulator fit for a simulator loop.

Conventions (the same in the FMU): inputs and outputs are perturbations about
trim in SI units, named as the record columns.  ``step(u)`` holds ``u`` over
``[t_k, t_k + dt)`` and returns the outputs at ``t_{k+1}``; :meth:`replay` returns
the outputs at every sample ``t_k`` with ``y[0]`` the initial output, the same
convention as ``scipy.signal.dlsim``.  Time is ``t0 + k dt`` from a step
counter, never a running sum.  Output delays are exact for held inputs: a delay
of ``(m + f) dt`` reads the state a fraction ``1 - f`` into an earlier step.
"""
from __future__ import annotations

import numpy as np

from .discrete import discretize, lifted_replay
from ..errors import InputError



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
    """

    def __init__(self, model, dt: float, method: str = "zoh", x0=None, t0: float = 0.0):
        if not (np.isfinite(dt) and dt > 0):
            raise InputError(f"dt = {dt}: the step must be a finite number > 0 s")
        if method not in ("zoh", "rk4"):
            raise InputError(f"method {method!r}: choose zoh or rk4")
        self.dt = float(dt)
        self.method = method
        self.t0 = float(t0)
        self._set_model(model)
        self.reset(x0)

    # -- model and discretisation ---------------------------------------
    def _set_model(self, model):
        if np.any(model.delays < 0) or np.any(model.input_delays != 0):
            raise InputError(
                f"Simulator: the model {model.structure.name} has "
                + ("a lead on a flap output" if np.any(model.delays < 0)
                   else "time shifts on its inputs")
                + ", which a step-by-step loop cannot apply causally; replay a whole "
                  "record with inflowsim.replay.replay, or drop the time-shift effects "
                  "(they describe the recording, not the rotor)")
        self.model = model
        self._load_matrices = None          # built on the first loads() call
        a, b, c = model.a, model.b, model.c
        self.n, self.m = b.shape
        self._ushape = (self.m,)
        phi, gam = discretize(a, b, self.dt, self.method)
        self.phi, self.gam = phi, gam
        pg = np.hstack([phi, gam])
        # [x+; y+; check]: the last row sums [x; u], so a NaN or infinite input (or
        # state) shows in one number the step reads without another array operation
        self._M = np.vstack([pg, c @ pg, np.ones((1, pg.shape[1]))])
        self._delay = self._delay_tables(model.delays)

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
        """Swap in another model of the same structure, keeping the state."""
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
        """Change the flight condition between steps; the discrete matrices follow."""
        if mu != self.model.constants.mu:
            self.set_model(self.model.with_mu(mu))

    # -- state ------------------------------------------------------------
    def reset(self, x0=None):
        """Back to step 0 with state ``x0`` (default zero)."""
        self._k = 0
        self._xu = np.zeros(self.n + self.m)
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
        return self.t0 + self._k * self.dt

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
        """Hold ``u`` (``model.inputs`` order, SI perturbations) over one step;
        return the six outputs at the new time."""
        xu = self._xu
        n = self.n
        # len() refuses None and scalars, and with it the assignment refuses every
        # other shape (a length-1 or 1 x m array would broadcast): cheaper than a
        # type and shape test, and free when the inputs are right
        try:
            if len(u) != self.m:
                raise ValueError
            xu[n:] = u
        except (TypeError, ValueError):
            self._inputs(u)                  # raises, saying what is wrong
            raise InputError(f"step: inputs must be {self.m} numbers") from None
        # ndarray.dot: about half the call overhead of @ for this small matrix-vector
        # product (bench/simulator.md), which more than pays for the checks
        out = self._M.dot(xu)
        check = out.item(-1)
        if check - check != 0.0:            # NaN or infinite (0 * NaN is NaN)
            raise InputError("step: inputs must be finite (a NaN or infinite value); "
                             "the state is unchanged")
        if self._delay is not None:
            self._push(xu[:n].copy(), np.array(u, dtype=float))
        xu[:n] = out[:n]
        self._k += 1
        y = out[n:-1]
        if self._delay is not None:
            y = self._apply_delays(y, self._k)
        return y

    def _inputs(self, u) -> np.ndarray:
        """``u`` as ``m`` floats, or one line saying what is wrong with it."""
        names = ", ".join(self.model.inputs)
        if u is None:
            raise InputError(f"step: inputs must be {self.m} numbers ({names}), got None")
        try:
            a = np.asarray(u, dtype=float)
        except (TypeError, ValueError):
            raise InputError(f"step: inputs must be {self.m} numbers ({names}), got "
                             f"{type(u).__name__}") from None
        if a.shape != (self.m,):
            raise InputError(f"step: inputs must be {self.m} numbers ({names}), got shape "
                             f"{a.shape}")
        return a

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
        u = np.asarray(u, dtype=float)
        if u.ndim != 2 or u.shape[1] != self.m:
            raise InputError(f"replay needs inputs of shape (N, {self.m}) "
                             f"({', '.join(self.model.inputs)})")
        if not np.all(np.isfinite(u)):
            raise InputError("replay: inputs contain NaN or infinite values")
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
