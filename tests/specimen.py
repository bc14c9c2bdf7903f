"""The paper's specimen as scenario text, shared by the tests that build scenarios from TOML.

Xu & Ervin (2013), Table 1: a polycarbonate cantilever, L = 109.2 mm, b = 9.93 mm,
h = 3.03 mm, E = 1834 MPa, rho = 951.98 kg/m^3, contactor at 0.4840 L with
k = 4030 N/m and a 0.229 mm gap (Case 3). ``BEAM`` is the ``[beam]`` table in SI
numbers; ``CONTACTOR`` the Case-3 contactor; :func:`write_scenario` writes a text
to a file for the command line.
"""

from __future__ import annotations

from pathlib import Path

BEAM = """
[beam]
length = 0.1092
width = 9.93e-3
height = 3.03e-3
youngs_modulus = 1834e6
density = 951.98
"""

CONTACTOR = """
[[contactors]]
position_ratio = 0.4840
stiffness = 4030
gap = 0.229e-3
side = "above"
"""


def write_scenario(directory: Path, text: str, name: str = "case.toml") -> Path:
    """Write ``text`` as ``directory / name`` (UTF-8) and return the path."""
    path = directory / name
    path.write_text(text, encoding="utf-8")
    return path
