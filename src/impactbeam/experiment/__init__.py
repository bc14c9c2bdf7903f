"""Measured records and identification: the workflow of the paper's section 4.

An experimenter (Xu & Ervin 2013, sections 3 and 4) measures

* a free-decay record (the beam released from a tip deflection, Case 0/13)
  -> natural frequencies (:func:`identify_frequencies`), damping ratio by
  logarithmic decrement (:func:`damping_log_decrement`, section 4.1 reports
  1.1 +/- 0.1 %) and the Young's modulus that makes the model's first
  frequency match (:func:`modulus_from_frequency`, section 4.1);
* a contact test (Case 3) -> the frequency of the contact portions
  (:func:`contact_frequency_from_record`) and the contact stiffness that gives
  the model the same contact-state fundamental
  (:func:`contact_stiffness_from_frequency`, section 4.2: 4030 N/m);
* the shaker's base acceleration (paper Fig. 3) -> the model driven by that
  trace (:func:`drive_with_trace`), compared with the measured deflection
  (:func:`compare`, the section-4 quantities side by side).

A :class:`Record` is one channel against time, in SI units: a deflection
[m] or a base acceleration [m/s^2]. :func:`load_record` reads CSV and netCDF.

Sign convention: a deflection record holds ``w`` at one point of the beam in
the model's convention (see the model page: measured from the rest position,
positive along +w). The comparison quantities are computed, as the metrics
of :mod:`impactbeam.result.metrics`, on ``u`` positive away from the first
contactor (``u = -w`` for a contactor "above"), so a contact shows as ``u``
below ``-gap``.
"""

from __future__ import annotations

from .identification import Identification, identify
from .compare import drive_with_trace, response_features, FEATURES, Comparison, compare, record_point
from .damping import DampingEstimate, damping_log_decrement
from .inversion import (
    modulus_from_frequency,
    contact_stiffness_from_frequency,
    contact_state_frequency,
    ContactFrequency,
    contact_frequency_from_record,
)
from .records import Record, load_record, MIN_SAMPLES, GAP_FACTOR
from .spectral import FrequencyEstimate, identify_frequencies

__all__ = [
    "identify",
    "Identification",
    "Record",
    "load_record",
    "MIN_SAMPLES",
    "GAP_FACTOR",
    "FrequencyEstimate",
    "identify_frequencies",
    "DampingEstimate",
    "damping_log_decrement",
    "modulus_from_frequency",
    "contact_stiffness_from_frequency",
    "contact_state_frequency",
    "ContactFrequency",
    "contact_frequency_from_record",
    "drive_with_trace",
    "response_features",
    "FEATURES",
    "Comparison",
    "compare",
    "record_point",
]
