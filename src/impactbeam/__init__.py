"""impactbeam: transient response of impacting beams by exact piecewise modal analysis."""
from .beam import Beam, Contactor, Support
from .modes import ModeSet, mode_set, scenario_modes
