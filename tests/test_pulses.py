"""Near-fault pulses against closed forms: peaks, end velocity and displacement, symmetry,
spectra and the large-gamma limit of the Mavroeidis-Papageorgiou pulse.

Velocities and displacements are integrated here with scipy's quad (independent of the
pulse code); the MP velocity is written out again from the paper to check the acceleration.
"""

import math

import numpy as np
import pytest
from scipy.integrate import quad

from rbm_cli.base.errors import RbmError
from rbm_cli.inputs import pulses
from rbm_cli.inputs.pulses import (
    cycloidal_pulse,
    mavroeidis_papageorgiou,
    mavroeidis_papageorgiou_duration,
    one_sine_duration,
    one_sine_pulse,
    ricker_duration,
    ricker_wavelet,
)

# quad warns of roundoff when an integral is ~0 to 1e-14 of its integrand: the asserts below
# compare with closed forms, so the warning says nothing more.
pytestmark = pytest.mark.filterwarnings("ignore::scipy.integrate.IntegrationWarning")


def _velocity_and_displacement_at_end(func, duration):
    """v(T) = int_0^T a dt and u(T) = int_0^T (T - s) a(s) ds, by adaptive quadrature."""
    opts = {"limit": 400, "epsabs": 1e-14, "epsrel": 1e-10}
    v, _ = quad(func, 0.0, duration, **opts)
    u, _ = quad(lambda s: (duration - s) * func(s), 0.0, duration, **opts)
    return v, u


@pytest.mark.parametrize("freq", [0.3, 1.0, 4.0])
def test_one_sine_closed_forms(freq):
    amp = 2.5
    w = 2 * math.pi * freq
    T = one_sine_duration(freq)
    assert T == pytest.approx(1 / freq)
    assert one_sine_pulse(T / 4, amp, freq) == pytest.approx(amp, rel=1e-15)
    assert one_sine_pulse(3 * T / 4, amp, freq) == pytest.approx(-amp, rel=1e-15)
    t = np.linspace(0, T, 4001)
    assert np.max(np.abs(one_sine_pulse(t, amp, freq))) <= amp * (1 + 1e-15)
    v, u = _velocity_and_displacement_at_end(lambda s: one_sine_pulse(s, amp, freq), T)
    assert abs(v) < 1e-12 * amp / w
    assert u == pytest.approx(amp * T / w, rel=1e-10)  # forward pulse: ends displaced
    assert one_sine_pulse(-1e-9, amp, freq) == 0.0
    assert one_sine_pulse(T + 1e-9, amp, freq) == 0.0
    np.testing.assert_array_equal(
        cycloidal_pulse(t, amp, freq, kind="A"), one_sine_pulse(t, amp, freq)
    )


@pytest.mark.parametrize("freq", [0.5, 2.0])
def test_cycloidal_b_closed_forms(freq):
    """Type B: peak A at 0, T/2, T; velocity and displacement return to 0 (forward and back)."""
    amp = 1.7
    w = 2 * math.pi * freq
    T = one_sine_duration(freq)
    assert cycloidal_pulse(0.0, amp, freq) == amp
    assert cycloidal_pulse(T / 2, amp, freq) == pytest.approx(-amp, rel=1e-15)
    assert cycloidal_pulse(T, amp, freq) == pytest.approx(amp, rel=1e-15)
    v, u = _velocity_and_displacement_at_end(lambda s: cycloidal_pulse(s, amp, freq), T)
    assert abs(v) < 1e-12 * amp / w
    assert abs(u) < 1e-12 * amp / w**2
    # velocity at T/4: (A / w) sin(w T / 4) = A / w
    v_quarter, _ = quad(lambda s: cycloidal_pulse(s, amp, freq), 0.0, T / 4, epsabs=1e-14)
    assert v_quarter == pytest.approx(amp / w, rel=1e-10)
    assert cycloidal_pulse(T * 1.0001, amp, freq) == 0.0


@pytest.mark.parametrize("freq", [0.4, 2.0])
def test_ricker_closed_forms(freq):
    amp = 3.0
    duration = ricker_duration(freq)
    t0 = duration / 2
    assert t0 == pytest.approx(1.5 / freq)
    assert ricker_wavelet(t0, amp, freq) == amp
    s = np.linspace(0, t0, 777)
    np.testing.assert_allclose(
        ricker_wavelet(t0 + s, amp, freq), ricker_wavelet(t0 - s, amp, freq), rtol=0, atol=1e-14
    )
    # zero crossings at t0 +- 1 / (sqrt(2) pi f)
    tz = t0 + 1 / (math.sqrt(2) * math.pi * freq)
    assert abs(ricker_wavelet(tz, amp, freq)) < 1e-14 * amp
    assert abs(ricker_wavelet(0.0, amp, freq)) < 2e-8 * amp
    # from rest, the cut leaves v(T) = 2 A t0 e^{-(pi f t0)^2} and u(T) = t0 v(T): tiny
    v, u = _velocity_and_displacement_at_end(lambda x: ricker_wavelet(x, amp, freq), duration)
    v_cut = 2 * amp * t0 * math.exp(-((math.pi * freq * t0) ** 2))
    assert v_cut < 1e-9 * amp / freq
    assert v == pytest.approx(v_cut, rel=1e-3, abs=1e-15)
    assert u == pytest.approx(t0 * v_cut, rel=1e-3, abs=1e-15)
    # the most negative value: -2 A e^{-3/2} at u = sqrt(3/2)
    dense = ricker_wavelet(np.linspace(0, duration, 200001), amp, freq)
    assert dense.min() == pytest.approx(-2 * amp * math.exp(-1.5), rel=1e-8)


def test_ricker_spectrum_peaks_at_fp():
    """The Fourier amplitude of the sampled wavelet is largest at f_p (within one bin)."""
    fp, dt = 2.0, 0.001
    t = np.arange(0, 64.0, dt)  # 1/64 Hz bins
    a = ricker_wavelet(t, 1.0, fp, shift_s=32.0)
    spec = np.abs(np.fft.rfft(a))
    freqs = np.fft.rfftfreq(t.size, dt)
    assert abs(freqs[np.argmax(spec)] - fp) <= 1 / 64.0


def _mp_velocity(t, freq, gamma, nu):
    """MP (2003) velocity pulse with unit amplitude, t0 = gamma / (2 f)."""
    tau = t - gamma / (2 * freq)
    inside = np.abs(tau) <= gamma / (2 * freq)
    v = 0.5 * (1 + np.cos(2 * np.pi * freq * tau / gamma)) * np.cos(2 * np.pi * freq * tau + nu)
    return np.where(inside, v, 0.0)


@pytest.mark.parametrize(
    ("gamma", "nu"), [(1.5, 0.0), (2.0, math.pi / 2), (3.0, 1.0), (5.5, -2.0), (1.01, 3.0)]
)
def test_mp_is_derivative_of_velocity_and_peak_is_amplitude(gamma, nu):
    freq, amp = 0.8, 4.0
    T = mavroeidis_papageorgiou_duration(freq, gamma)
    assert T == pytest.approx(gamma / freq)
    t = np.linspace(0.0, T, 400001)
    a = mavroeidis_papageorgiou(t, amp, freq, gamma, nu)
    peak = np.max(np.abs(a))
    assert peak <= amp * (1 + 1e-10)
    assert peak >= amp * (1 - 1e-8)  # dense sampling reaches the peak to ~(dt f)^2
    # derivative of the paper's velocity by central differences, normalised to its peak
    h = 1e-6
    dv = (_mp_velocity(t + h, freq, gamma, nu) - _mp_velocity(t - h, freq, gamma, nu)) / (2 * h)
    dv[[0, -1]] = 0.0
    scale = amp / np.max(np.abs(dv))
    np.testing.assert_allclose(a, scale * dv, rtol=0, atol=1e-6 * amp)
    # the pulse starts and ends at rest
    assert abs(a[0]) < 1e-12 and abs(a[-1]) < 1e-12
    v, _ = _velocity_and_displacement_at_end(
        lambda s: mavroeidis_papageorgiou(s, amp, freq, gamma, nu), T
    )
    assert abs(v) < 1e-10 * amp / freq


def test_mp_symmetry():
    """nu = 0: even velocity, odd acceleration about t0; nu = pi/2: the other way round."""
    freq, gamma, amp = 1.3, 2.4, 1.0
    t0 = gamma / (2 * freq)
    s = np.linspace(0, t0, 1001)
    odd = mavroeidis_papageorgiou(t0 + s, amp, freq, gamma, 0.0)
    np.testing.assert_allclose(
        odd, -mavroeidis_papageorgiou(t0 - s, amp, freq, gamma, 0.0), atol=1e-13
    )
    even = mavroeidis_papageorgiou(t0 + s, amp, freq, gamma, math.pi / 2)
    np.testing.assert_allclose(
        even, mavroeidis_papageorgiou(t0 - s, amp, freq, gamma, math.pi / 2), atol=1e-13
    )
    flipped = mavroeidis_papageorgiou(s, -amp, freq, gamma, 0.7)
    np.testing.assert_array_equal(flipped, -mavroeidis_papageorgiou(s, amp, freq, gamma, 0.7))


def test_mp_large_gamma_tends_to_modulated_sine():
    """a / peak -> -sin(2 pi f tau + nu) (1 + cos(2 pi f tau / gamma)) / 2, error ~ 1/gamma."""
    freq, nu = 1.0, 0.4
    errors = []
    for gamma in (20.0, 200.0):
        t0 = gamma / (2 * freq)
        t = np.linspace(0, 2 * t0, 200001)
        tau = t - t0
        limit = (
            -np.sin(2 * np.pi * freq * tau + nu)
            * 0.5
            * (1 + np.cos(2 * np.pi * freq * tau / gamma))
        )
        a = mavroeidis_papageorgiou(t, 1.0, freq, gamma, nu)
        errors.append(np.max(np.abs(a - limit / np.max(np.abs(limit)))))
    assert errors[1] < 0.02
    assert errors[1] < errors[0] / 5


@pytest.mark.parametrize(
    ("call", "fragment"),
    [
        (lambda: one_sine_pulse(0.1, 1.0, 0.0), "frequency_hz must be > 0"),
        (lambda: cycloidal_pulse(0.1, 1.0, -1.0), "frequency_hz must be > 0"),
        (lambda: cycloidal_pulse(0.1, 1.0, 1.0, kind="C"), "kind must be 'A' or 'B'"),
        (lambda: ricker_wavelet(0.1, float("nan"), 1.0), "amplitude must be finite"),
        (lambda: ricker_wavelet(0.1, 1.0, 1.0, shift_s=0.0), "shift_s must be > 0"),
        (lambda: mavroeidis_papageorgiou(0.1, 1.0, 1.0, 1.0, 0.0), "gamma must be > 1"),
        (lambda: mavroeidis_papageorgiou(0.1, 1.0, 1.0, 2.0, math.inf), "nu must be finite"),
        (lambda: mavroeidis_papageorgiou_duration(1.0, 0.5), "gamma must be > 1"),
    ],
)
def test_bad_parameters_refused(call, fragment):
    with pytest.raises(RbmError, match=fragment):
        call()


def test_registry_and_scalar_returns():
    for name, (func, duration) in pulses.PULSES.items():
        kwargs = {"gamma": 2.0, "nu": 0.0} if name == "mavroeidis-papageorgiou" else {}
        dur = duration(1.0, **({"gamma": 2.0} if kwargs else {}))
        assert dur > 0
        assert isinstance(func(0.3 * dur, 1.0, 1.0, **kwargs), float)
        assert func(dur * 1.001, 1.0, 1.0, **kwargs) == 0.0
