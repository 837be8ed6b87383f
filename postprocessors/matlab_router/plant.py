"""Speed-loop pieces of the Angel-11 DC-servo router: plant, IP controllers, gain design.

Units: speeds are encoder counts (×4 quadrature, 1024 per motor revolution) per
5 ms sample, "counts/Ts" (Angel-11 §2.3: the thesis's "pulsos/s" are really
counts per Ts); the command ``u`` is the PWM command in percent, −100…+100.

Design notes: docs/internals.md, ``postprocessors/matlab_router/plant.py``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
import numpy.typing as npt

from camtool.model.errors import UsageError

TS_S = 0.005
"""Servo sample period, s (Angel-11 §2.6: ``#define Ts 0.005``, Timer5 preload 53036)."""

Law = Literal["firmware", "ideal"]
LAWS: tuple[str, ...] = ("firmware", "ideal")
"""Speed-controller laws: the firmware's integer code (R10) or eq. 4.27 with Table 4.1 gains."""

FIRMWARE_GAINS = (28, 159)
"""``(kid, kpd)`` × 1000 of all three slave listings (L5104–L5108, L5813, L6345)."""


@dataclass(frozen=True)
class Plant:
    """First-order discrete speed plant ``ω[k+1] = pole·ω[k] + gain·u[k]`` (Angel-11 §5.1, R9).

    Attributes:
        pole: Discrete pole, ``0 <= pole < 1`` (0.9283 in eq. 4.34).
        gain: Input gain, counts/Ts per % (0.6986 in eq. 4.34).
    """

    pole: float
    gain: float

    def __post_init__(self) -> None:
        if not (0.0 <= self.pole < 1.0 and self.gain > 0.0):
            raise UsageError(
                f"plant needs 0 <= pole < 1 and gain > 0, got {self.pole!r}, {self.gain!r}"
            )

    @classmethod
    def from_analog(cls, a: float, tau_s: float, *, ts_s: float = TS_S) -> Plant:
        """Zero-order-hold discretisation of ``A/(τs + 1)``.

        ``pole = exp(−Ts/τ)``, ``gain = A·(1 − pole)`` (Angel-11 §5.1 (D): the
        thesis numerator 0.6986 has the ZOH form, not Tustin's).

        Args:
            a: Static gain A, counts/Ts per %.
            tau_s: Time constant τ, s, ``> 0``.
            ts_s: Sample period, s.

        Raises:
            UsageError: If ``tau_s`` or ``ts_s`` is not positive, or ``a <= 0``.
        """
        if not (tau_s > 0 and ts_s > 0 and a > 0):
            raise UsageError(f"plant needs A > 0, tau > 0, Ts > 0; got {a!r}, {tau_s!r}, {ts_s!r}")
        pole = math.exp(-ts_s / tau_s)
        return cls(pole=pole, gain=a * (1.0 - pole))

    @property
    def dc_gain(self) -> float:
        """Steady-state speed per % of command, counts/Ts per % (A)."""
        return self.gain / (1.0 - self.pole)

    def tau_s(self, ts_s: float = TS_S) -> float:
        """Equivalent analog time constant, s (``−Ts/ln(pole)``; ``0`` for pole 0)."""
        return -ts_s / math.log(self.pole) if self.pole > 0 else 0.0


THESIS_PLANT = Plant(pole=0.9283, gain=0.6986)
"""G_p(z) = 0.6986/(z − 0.9283), Angel-11 eq. 4.34 (all three axes in the thesis)."""


@dataclass(frozen=True)
class IPGains:
    """Gains of the IP speed controller (Angel-11 §4.5, §5.2, Table 4.1).

    Attributes:
        ki: Analog integral gain K_i, % per (counts/Ts)·s.
        kp: Analog proportional gain K_p, % per counts/Ts.
        kid: Digital integral gain ``K_id = K_i·T`` (eq. 4.30).
        kpd: Digital proportional gain ``K_pd = K_p − K_id/2`` (eq. 4.29).
        wn: Natural frequency ω_n the gains were designed for, rad/s.
    """

    ki: float
    kp: float
    kid: float
    kpd: float
    wn: float


TABLE_4_1: tuple[IPGains, IPGains, IPGains] = (
    IPGains(ki=3.5099, kp=0.1069, kid=0.017549, kpd=0.098125, wn=22.63),
    IPGains(ki=5.6304, kp=0.1732, kid=0.028152, kpd=0.159124, wn=22.63),
    IPGains(ki=3.2509, kp=0.10074, kid=0.0162, kpd=0.09264, wn=22.63),
)
"""Table 4.1 of Angel-11 (L2872–L2880), verbatim, in axis order X, Y, Z."""


def digital_gains(ki: float, kp: float, sample_s: float = TS_S) -> tuple[float, float]:
    """Digital IP gains from analog ones: ``(K_id, K_pd) = (K_i·T, K_p − K_i·T/2)``.

    Angel-11 eqs. 4.29–4.30 (R11); Table 4.1's digital columns follow from its
    analog ones this way.
    """
    kid = ki * sample_s
    return kid, kp - kid / 2.0


def design_ip(
    a: float, tau_s: float, settling_s: float, xi: float, sample_s: float = TS_S
) -> IPGains:
    """Design IP speed-loop gains for the plant ``A/(τs + 1)`` (Angel-11 §5.2, R11).

    ``ω_n = 4/(ξ·t_s)`` (2 % settling, eq. 4.44), ``K_i = ω_n²·τ/A`` (4.39),
    ``K_p = (2ξω_nτ − 1)/A`` (4.40), then the digital gains of
    :func:`digital_gains`. ξ = 0.707, t_s = 0.25 s gives ω_n = 22.63 rad/s.

    Args:
        a: Plant static gain A, counts/Ts per %.
        tau_s: Plant time constant, s.
        settling_s: Wanted 2 % settling time t_s, s.
        xi: Damping ratio ξ (0.707 for < 5 % overshoot).
        sample_s: Controller period T, s.

    Returns:
        The analog and digital gains and ω_n.

    Raises:
        UsageError: If a parameter is not positive.
    """
    if min(a, tau_s, settling_s, xi, sample_s) <= 0:
        raise UsageError(
            f"design_ip needs positive A, tau, ts, xi, T; got {a!r}, {tau_s!r}, "
            f"{settling_s!r}, {xi!r}, {sample_s!r}"
        )
    wn = 4.0 / (xi * settling_s)
    ki = wn * wn * tau_s / a
    kp = (2.0 * xi * wn * tau_s - 1.0) / a
    kid, kpd = digital_gains(ki, kp, sample_s)
    return IPGains(ki=ki, kp=kp, kid=kid, kpd=kpd, wn=wn)


def plant_from_gains(
    ki: float, kp: float, *, settling_s: float = 0.25, xi: float = 0.707
) -> tuple[float, float]:
    """Back-solve the plant ``(A, τ)`` a pair of analog IP gains was designed for.

    Inverts eqs. 4.39–4.40: ``A = 1/(2ξω_n·K_i/ω_n² − K_p)``, ``τ = K_i·A/ω_n²``.
    Angel-11 §5.2 (D): Table 4.1 gives X ≈ (8.90, 0.0610 s), Y ≈ (5.60, 0.0615 s),
    Z ≈ (9.77, 0.0620 s).

    Args:
        ki: Analog K_i.
        kp: Analog K_p.
        settling_s: The design's t_s, s.
        xi: The design's ξ.

    Returns:
        ``(A, tau_s)``: static gain, counts/Ts per %, and time constant, s.

    Raises:
        UsageError: If the gains imply a non-positive A or τ.
    """
    wn = 4.0 / (xi * settling_s)
    denom = 2.0 * xi * wn * ki / (wn * wn) - kp
    if denom <= 0 or ki <= 0:
        raise UsageError(f"gains Ki={ki!r}, Kp={kp!r} imply no positive first-order plant")
    a = 1.0 / denom
    return a, ki * a / (wn * wn)


def per_axis_plants(ts_s: float = TS_S) -> tuple[Plant, Plant, Plant]:
    """The X, Y, Z plants back-solved from Table 4.1 (Angel-11 §5.2 (D), R9), ZOH at ``ts_s``."""
    models = (plant_from_gains(g.ki, g.kp) for g in TABLE_4_1)
    x, y, z = (Plant.from_analog(a, tau, ts_s=ts_s) for a, tau in models)
    return x, y, z


class FirmwareIP:
    """The slaves' ``CONTROL_IP_VELOCIDAD`` in exact integer arithmetic (Angel-11 §4.5 (C), R10).

    Per 5 ms tick, with ``velAc`` the measured speed magnitude (counts/Ts)::

        INTE += (|Ref| − velAc)·kid;  u = (u + INTE − velAc·kpd)/1000  (C division)
        u = clamp(u, 0, 100);  if Ref < 0: u = −u;  if Ref == 0: u = 0

    ``INTE`` is never clamped nor reset (windup carries from move to move) and
    the signed ``u`` is carried into the next tick, both as in the listing. The
    ``Ref == 0`` rule is the X listing's (L5574); the Y/Z listings comment it out.
    Instances hold state: make one per simulated axis.
    """

    __slots__ = ("inte", "kid", "kpd", "u")

    def __init__(self, kid: int = FIRMWARE_GAINS[0], kpd: int = FIRMWARE_GAINS[1]) -> None:
        self.kid = int(kid)
        self.kpd = int(kpd)
        self.inte = 0
        self.u = 0

    def step(self, ref: int, vel_meas: int, w: float) -> int:
        """One tick: PWM command, %, from the reference and the measured speed magnitude.

        ``w`` (the signed plant speed) is not used: the firmware only sees ``vel_meas``.
        """
        self.inte += (abs(ref) - vel_meas) * self.kid
        s = self.u + self.inte - vel_meas * self.kpd
        u = abs(s) // 1000
        if s < 0:
            u = -u
        u = 100 if u >= 100 else (0 if u < 0 else u)
        if ref < 0:
            u = -u
        if ref == 0:
            u = 0
        self.u = u
        return u


class IdealIP:
    """Eq. 4.27, ``u(k) = u(k−1) − K_pd·[ω(k) − ω(k−1)] + K_id·[ω_ref(k) − ω(k)]`` (Angel-11 §4.5).

    Floats, signed speeds, ``u`` clamped to ±100 % (the PWM range; clamping the
    carried ``u`` is the anti-windup of the incremental form). ``Ref == 0``
    switches the motor off, as the firmware does at the end of a move.
    Instances hold state: make one per simulated axis.
    """

    __slots__ = ("kid", "kpd", "u", "w_prev")

    def __init__(self, gains: IPGains) -> None:
        self.kid = gains.kid
        self.kpd = gains.kpd
        self.u = 0.0
        self.w_prev = 0.0

    def step(self, ref: int, vel_meas: int, w: float) -> float:
        """One tick: PWM command, %, from the reference and the signed speed ``w``, counts/Ts."""
        u = self.u - self.kpd * (w - self.w_prev) + self.kid * (ref - w)
        u = 100.0 if u > 100.0 else (-100.0 if u < -100.0 else u)
        self.w_prev = w
        if ref == 0:
            u = 0.0
        self.u = u
        return u


def open_loop_step(plant: Plant, u_pct: float, n: int) -> npt.NDArray[np.float64]:
    """Speed response to a constant command from rest (Angel-11 §5.1 identification).

    Args:
        plant: The plant.
        u_pct: Command, %.
        n: Number of samples.

    Returns:
        Read-only ``(n + 1,) float64`` speeds, counts/Ts; element 0 is 0.
    """
    k = np.arange(n + 1, dtype=np.float64)
    out = plant.dc_gain * u_pct * (1.0 - plant.pole**k)
    out.flags.writeable = False
    return out


def closed_loop_step(
    plant: Plant,
    ref: int,
    n: int,
    *,
    law: Law = "firmware",
    gains: IPGains | None = None,
    firmware_gains: tuple[int, int] = FIRMWARE_GAINS,
) -> npt.NDArray[np.float64]:
    """Speed response of the IP loop to a constant reference from rest (Angel-11 §5.3, Fig 4.12).

    The controller sees the integer count advance per sample, as the firmware's
    ``velAc``; ``ideal`` sees the exact plant speed.

    Args:
        plant: The plant.
        ref: Speed reference, counts/Ts (signed).
        n: Number of samples.
        law: ``"firmware"`` (integer law, ``firmware_gains``) or ``"ideal"``
            (eq. 4.27 with ``gains``).
        gains: Digital gains for ``law="ideal"``.
        firmware_gains: ``(kid, kpd)`` × 1000 for ``law="firmware"``.

    Returns:
        Read-only ``(n + 1,) float64`` speeds, counts/Ts; element 0 is 0.

    Raises:
        UsageError: If ``law`` is unknown, or ``ideal`` without ``gains``.
    """
    ctrl = make_controller(law, gains=gains, firmware_gains=firmware_gains)
    out = np.zeros(n + 1)
    w = pos = 0.0
    enc = vel = 0
    for k in range(1, n + 1):
        w = plant.pole * w + plant.gain * ctrl.step(ref, vel, w)
        pos += w
        e = math.floor(pos)
        vel, enc = abs(e - enc), e
        out[k] = w
    out.flags.writeable = False
    return out


def make_controller(
    law: Law | str,
    *,
    gains: IPGains | None = None,
    firmware_gains: tuple[int, int] = FIRMWARE_GAINS,
) -> FirmwareIP | IdealIP:
    """A fresh controller for one axis.

    Raises:
        UsageError: If ``law`` is not one of :data:`LAWS`, or ``ideal`` lacks ``gains``.
    """
    if law == "firmware":
        return FirmwareIP(*firmware_gains)
    if law == "ideal":
        if gains is None:
            raise UsageError("the ideal IP law needs gains (e.g. TABLE_4_1[1] or design_ip(...))")
        return IdealIP(gains)
    raise UsageError(f"unknown speed-controller law {law!r}; valid: {', '.join(LAWS)}")
