"""The paper's inputs and published values: the specimen (section 3), Table 1, and the reference numbers
of Table 2, section 4 and the paper's statements (never used as inputs; only compared with).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

__all__ = [
    "EXAMPLES_DIR",
    "G",
    "PAPER_CONVERGENCE",
    "PAPER_FREQUENCIES",
    "PAPER_REFIT",
    "PAPER_TRENDS",
    "REFERENCE_CASE",
    "SECTION4",
    "SPECIMEN",
    "TABLE1",
    "TABLE2_MEASURED",
    "Table2Row",
    "TableOneCase",
]


G = 9.80665  # standard gravity [m/s^2]

#: ``examples/`` of the source tree (absent in an installed wheel).
EXAMPLES_DIR = Path(__file__).resolve().parents[3] / "examples"


#: The ABS specimen of section 3 and the model parameters of section 4 (SI).
SPECIMEN: dict[str, float] = {
    "length": 0.10920,  # m (109.20 mm)
    "width": 9.93e-3,  # m
    "height": 3.03e-3,  # m
    "youngs_modulus": 1834e6,  # Pa (Quickparts value, section 3)
    "density": 951.98,  # kg/m^3
    "contact_position_ratio": 0.4840,  # a / L (section 3)
    "contact_stiffness": 4030.0,  # N/m (matched contact-state frequency, section 4.2)
    "damping_free": 0.011,  # section 4.1 (1.1 +- 0.1 %)
    "damping_contact": 0.02,  # section 4.2
}


@dataclass(frozen=True)
class TableOneCase:
    """One row of Table 1 (SI units; None where the paper says n/a).

    Attributes
    ----------
    number : int
    amplitude : float or None, [m/s^2]
        Half-sine base acceleration peak (None for the release tests).
    duration : float or None, [s]
    gap : float or None, [m]
        None: no contactor.
    initial_tip_displacement : float or None, [m]
        Cases 0 and 13: release from a 2 mm tip deflection.
    """

    number: int
    amplitude: float | None
    duration: float | None
    gap: float | None
    initial_tip_displacement: float | None = None

    @property
    def label(self) -> str:
        """Short description, e.g. ``"15 g, 15 ms, gap 0.229 mm"``."""
        if self.initial_tip_displacement is not None:
            return f"release from {self.initial_tip_displacement * 1e3:g} mm tip deflection"
        assert self.amplitude is not None and self.duration is not None
        gap = "no contactor" if self.gap is None else f"gap {self.gap * 1e3:.3f} mm"
        return f"{self.amplitude / G:g} g, {self.duration * 1e3:g} ms, {gap}"


_MM = 1e-3
_MS = 1e-3
#: Table 1 of the paper (Case 3 is the reference case).
TABLE1: tuple[TableOneCase, ...] = (
    TableOneCase(0, None, None, None, 2.0 * _MM),
    TableOneCase(1, 9 * G, 15 * _MS, None),
    TableOneCase(2, 15 * G, 15 * _MS, 0.102 * _MM),
    TableOneCase(3, 15 * G, 15 * _MS, 0.229 * _MM),
    TableOneCase(4, 15 * G, 10 * _MS, 0.229 * _MM),
    TableOneCase(5, 15 * G, 5 * _MS, 0.229 * _MM),
    TableOneCase(6, 10 * G, 15 * _MS, 0.229 * _MM),
    TableOneCase(7, 5 * G, 15 * _MS, 0.229 * _MM),
    TableOneCase(8, 12.5 * G, 15 * _MS, 0.229 * _MM),
    TableOneCase(9, 15 * G, 15 * _MS, 0.0),
    TableOneCase(10, 15 * G, 15 * _MS, 0.432 * _MM),
    TableOneCase(11, 15 * G, 15 * _MS, 0.686 * _MM),
    TableOneCase(12, 15 * G, 15 * _MS, None),
    TableOneCase(13, None, None, None, 2.0 * _MM),
)
REFERENCE_CASE = 3


#: Natural frequencies of the specimen, free state (sections 3 and 4.1) [Hz].
PAPER_FREQUENCIES: dict[str, Any] = {
    "computed_hz": (57.31, 359.13),
    "measured_hz": (57.13, 355.96),
    "measured_uncertainty_hz": 2.20,
}


@dataclass(frozen=True)
class Table2Row:
    """One measured row of Table 2 (SI; None where "Not comparable").

    Deflections are from the contactor surface, positive away from it.

    Attributes
    ----------
    group : str
        The parameter the rows of the group vary (e.g. "gap size").
    value : str
        The row's value of that parameter, as printed in the paper.
    case : int
        The Table 1 case of the row.
    max_response : float, [m]
    free_duration : float or None, [s]
    min_response : float or None, [m]
    contact_duration : float or None, [s]
    """

    group: str
    value: str
    case: int
    max_response: float
    free_duration: float | None
    min_response: float | None
    contact_duration: float | None


#: Table 2: experimental results for the three examined parameters (measured values).
TABLE2_MEASURED: tuple[Table2Row, ...] = (
    Table2Row("pulse duration", "15 ms", 3, 1.4554e-3, 0.0187, -0.0828e-3, 0.0040),
    Table2Row("pulse duration", "10 ms", 4, 1.3232e-3, 0.0147, -0.0551e-3, 0.0040),
    Table2Row("pulse duration", "5 ms", 5, 1.1023e-3, 0.0122, -0.0620e-3, 0.0038),
    Table2Row("pulse amplitude", "10 g", 6, 1.0338e-3, 0.0165, -0.1173e-3, 0.0047),
    Table2Row("pulse amplitude", "12.5 g", 8, 1.2344e-3, 0.0194, -0.0759e-3, 0.0040),
    Table2Row("pulse amplitude", "15 g", 3, 1.4554e-3, 0.0187, -0.0828e-3, 0.0040),
    Table2Row("gap size", "0.000 mm", 9, 0.2323e-3, None, None, None),
    Table2Row("gap size", "0.229 mm", 3, 1.4580e-3, 0.0187, -0.0828e-3, 0.0040),
    Table2Row("gap size", "0.432 mm", 10, 1.6434e-3, 0.0200, -0.0599e-3, 0.0022),
)

#: Section 4: the paper's simulated and measured values (SI).
SECTION4: dict[int, dict[str, dict[str, float]]] = {
    12: {  # section 4.1, Fig. 7 (no contactor)
        "simulated": {"first_peak": 1.08e-3, "first_negative_peak": -1.26e-3, "negative_lobe_duration": 0.01012},
        "measured": {"first_peak": 1.24e-3, "first_negative_peak": -1.15e-3, "negative_lobe_duration": 0.01052},
    },
    3: {  # section 4.2, Fig. 8 (raw parameters)
        "simulated": {"first_peak": 1.237e-3, "min_response": -0.1703e-3, "contact_duration": 0.00397},
        "measured": {"first_peak": 1.469e-3, "min_response": -0.08275e-3, "contact_duration": 0.004},
    },
}

#: Section 4: convergence statements.
PAPER_CONVERGENCE: dict[str, float] = {
    "no_contact_first_peak_2_vs_8_modes_percent": 0.01,
    "modes_without_contact": 4,
    "modes_with_contact": 8,
}

#: Section 4.2: the refit experiment (k = 7000 N/m and a 20 % stronger pulse).
PAPER_REFIT: dict[str, float] = {
    "contact_stiffness": 7000.0,
    "pulse_factor": 1.2,
    "free_state_difference_percent": 6.0,
    "contact_state_difference_percent": 17.0,
}

#: Section 2: the trend sentences of the seven-parameter study [24], by parameter.
PAPER_TRENDS: dict[str, str] = {
    "height": "For increasing beam height h, structural stiffness enlarges, so the cycle time and the maximum "
    "deflection decrease. Also, the more flexible the structure is, the more sensitivity to the contact stiffness k.",
    "modulus": "Similar trends are shown for increasing elastic modulus E.",
    "stiffness": "With increasing contact stiffness k, the system stiffness increases, the cycle time periods "
    "decrease, and less contact time occurs. For higher k values, two or three impacts may exist in each cycle.",
    "location": "For any boundary, the contact location a is the parameter that most affects impact and rebound "
    "behaviors. [...] placing the contactor at a point of maximum deflection causes the greatest rebound response.",
    "damping": "Increasing the system damping drastically decreases all amplitudes as well as the response complexity.",
    "duration": "Increasing pulse duration will extend the cycle time and amplify the structure deflection. If the "
    "duration is long enough, the beam will vibrate around a balanced position in free motion during the applied forcing.",
    "clearance": "For any boundary condition, increasing gap size will shorten the cycle time and the time portion in "
    "the contact state; the deformation amplitude dramatically increases in the contact state.",
}
