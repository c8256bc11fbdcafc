"""Mesh stiffness waveforms as Fourier series.

K(theta) / Km = 1 + sum_h a_h cos(h theta) + b_h sin(h theta).

theta = Omega tau is the mesh phase. The paper's sine wave (Eq. 4) is one harmonic. The rectangular
wave (double tooth contact for a fraction ``contact_ratio - 1`` of each mesh period, single contact
otherwise) is truncated after ``harmonics`` terms with Lanczos sigma factors, which keep the
right-hand side continuous in time (so fixed-step RK4 keeps its order) and suppress Gibbs ringing.
"""

from __future__ import annotations

import math

import numpy as np

from geardyn.models.params import Mesh


def harmonics_needed(mesh: Mesh) -> int:
    """Number of Fourier terms the mesh's waveform uses."""
    return 1 if mesh.waveform == "sine" else mesh.harmonics


def fourier_coefficients(mesh: Mesh, n_harmonics: int) -> tuple[np.ndarray, np.ndarray]:
    """Relative cosine and sine coefficients (a_h, b_h), h = 1..n_harmonics, of K/Km - 1."""
    a = np.zeros(n_harmonics)
    b = np.zeros(n_harmonics)
    rel = mesh.stiffness_amplitude / mesh.mean_stiffness
    phi = mesh.stiffness_phase
    if mesh.waveform == "sine":
        # sin(theta + phi) = sin(phi) cos(theta) + cos(phi) sin(theta)
        a[0] = rel * math.sin(phi)
        b[0] = rel * math.cos(phi)
        return a, b
    duty = mesh.contact_ratio - 1.0
    n = min(mesh.harmonics, n_harmonics)
    for h in range(1, n + 1):
        sigma = np.sinc(h / (n + 1))  # Lanczos factor sin(pi x)/(pi x)
        w = rel * sigma * 4.0 * math.sin(h * math.pi * duty) / (h * math.pi)
        # w cos(h (theta + phi)) = w cos(h phi) cos(h theta) - w sin(h phi) sin(h theta)
        a[h - 1] = w * math.cos(h * phi)
        b[h - 1] = -w * math.sin(h * phi)
    return a, b


def evaluate(a: np.ndarray, b: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """K/Km at mesh phases theta (for plots and tests)."""
    h = np.arange(1, a.size + 1)[:, None]
    th = np.asarray(theta, dtype=float)[None, ...]
    return 1.0 + np.sum(a[:, None] * np.cos(h * th) + b[:, None] * np.sin(h * th), axis=0)
