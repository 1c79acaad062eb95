"""Eq. 1 of Li, Zhang & Goldman 2013 (Science 339, 1408) as the paper writes it, with its
generic coefficients (supplementary Table S2; shared/LAWS.md): the reference the rft tests
compare the engine with (written here from the formula, not from the engine's code)."""

from __future__ import annotations

import numpy as np

A00, A10, B11, B01, BM11 = 0.206, 0.169, 0.212, 0.358, 0.055
C11, C01, CM11, D10 = -0.124, 0.253, 0.007, 0.088


def alpha_paper(beta: np.ndarray, gamma: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(alpha_x, alpha_z) of eq. 1: beta the line's angle, gamma the velocity's angle below
    +x; the paper's Fourier series with numpy's trigonometry."""
    az = (
        A00
        + A10 * np.cos(2 * beta)
        + B11 * np.sin(2 * beta + gamma)
        + B01 * np.sin(gamma)
        + BM11 * np.sin(-2 * beta + gamma)
    )
    ax = (
        C11 * np.cos(2 * beta + gamma)
        + C01 * np.cos(gamma)
        + CM11 * np.cos(-2 * beta + gamma)
        + D10 * np.sin(2 * beta)
    )
    return ax, az
