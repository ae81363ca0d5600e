"""The few unit conversions used at the edges (CLI, presets, plots). Inside, everything is SI."""

from __future__ import annotations

import math

RPM_TO_RAD_PER_S = 2.0 * math.pi / 60.0
ZERO_CELSIUS = 273.15
MICRO = 1e-6


def rpm_to_rad_per_s(speed_rpm):
    """Rotational speed: rpm → rad/s."""
    return speed_rpm * RPM_TO_RAD_PER_S


def rad_per_s_to_rpm(omega):
    """Rotational speed: rad/s → rpm."""
    return omega / RPM_TO_RAD_PER_S


def celsius_to_kelvin(t_c):
    """Temperature: °C → K."""
    return t_c + ZERO_CELSIUS


def kelvin_to_celsius(t_k):
    """Temperature: K → °C."""
    return t_k - ZERO_CELSIUS


def deg_to_rad(angle_deg):
    """Angle: degrees → radians."""
    return angle_deg * (math.pi / 180.0)


def rad_to_deg(angle_rad):
    """Angle: radians → degrees."""
    return angle_rad * (180.0 / math.pi)


def um_to_m(length_um):
    """Length: µm → m."""
    return length_um * MICRO


def m_to_um(length_m):
    """Length: m → µm."""
    return length_m / MICRO
