"""Every public function and method documents each of its parameters (numpydoc).

Public means: the names in the ``__all__`` of the modules that form the API
(:data:`API_MODULES`: the package namespace, the solver's entry points and its
dense output, the result, metrics, plots, model, units, measurements, fits,
sweeps and the paper's study); for classes, their public methods and the
constructor's parameters (in the class docstring, under "Parameters" or, for a
dataclass, "Attributes"). The solver's implementation modules (engine, state
spaces, Ritz basis, the solve_ivp reference) are documented for developers but
are not API.
The "Parameters" section is parsed with numpydoc's own reader, so a name that
is misspelt, missing or documented under the wrong heading fails here, as in
python-control's docstring test.
"""

from __future__ import annotations

import importlib
import inspect

import pytest

numpydoc_docscrape = pytest.importorskip("numpydoc.docscrape")

API_MODULES = (
    "impactbeam",
    "impactbeam.solver",
    "impactbeam.simulation",
    "impactbeam.solver.solution",
    "impactbeam.result",
    "impactbeam.result.simulation_result",
    "impactbeam.result.files",
    "impactbeam.result.metrics",
    "impactbeam.result.stress",
    "impactbeam.result.timegrid",
    "impactbeam.plot",
    "impactbeam.plot.response",
    "impactbeam.plot.study",
    "impactbeam.plot.modes",
    "impactbeam.plot.periodic",
    "impactbeam.plot.sweep",
    "impactbeam.modal",
    "impactbeam.modal.modeset",
    "impactbeam.model",
        "impactbeam.units",
    "impactbeam.experiment.damping",
    "impactbeam.experiment",
    "impactbeam.fit",
    "impactbeam.sweeps",
    "impactbeam.scenario",
    "impactbeam.paper",
    "impactbeam.explore",
)


def _documented(doc: str | None, sections: tuple[str, ...] = ("Parameters", "Other Parameters")) -> set[str]:
    if not doc:
        return set()
    parsed = numpydoc_docscrape.NumpyDocString(inspect.cleandoc(doc))
    names: set[str] = set()
    for section in sections:
        for p in parsed[section]:
            for name in p.name.split(","):
                names.add(name.strip().lstrip("*"))
    return names


def _required(fn) -> list[str]:
    try:
        sig = inspect.signature(fn)
    except (TypeError, ValueError):
        return []
    return [n for n, p in sig.parameters.items()
            if n not in ("self", "cls") and not n.startswith("_")]


def _public_callables() -> list[tuple[str, object, str | None]]:
    """(qualified name, callable, docstring holding its parameters)."""
    out = []
    seen = set()
    for modname in API_MODULES:
        mod = importlib.import_module(modname)
        for name in getattr(mod, "__all__", ()):
            obj = getattr(mod, name, None)
            if obj is None or id(obj) in seen or getattr(obj, "__module__", "").split(".")[0] != "impactbeam":
                continue
            seen.add(id(obj))
            if inspect.isclass(obj):
                if issubclass(obj, BaseException):
                    continue
                init = obj.__dict__.get("__init__")
                if init is not None or "__dataclass_fields__" in obj.__dict__:
                    out.append((f"{modname}.{name}", obj, obj.__doc__))
                for mname, member in vars(obj).items():
                    if mname.startswith("_") or not inspect.isfunction(member):
                        continue
                    # an override without a docstring inherits its base class's (inspect.getdoc)
                    out.append((f"{modname}.{name}.{mname}", member, inspect.getdoc(getattr(obj, mname))))
            elif inspect.isfunction(obj):
                out.append((f"{modname}.{name}", obj, obj.__doc__))
    return out


CALLABLES = _public_callables()


@pytest.mark.parametrize(("name", "fn", "doc"), CALLABLES, ids=[c[0] for c in CALLABLES])
def test_parameters_documented(name: str, fn, doc: str | None) -> None:
    required = _required(fn)
    if not required:
        return
    if doc is None:
        pytest.fail(f"{name}: no docstring")
    # a dataclass's fields are its constructor's parameters: "Parameters" or "Attributes"
    sections = ("Parameters", "Other Parameters", "Attributes") if inspect.isclass(fn) else ("Parameters", "Other Parameters")
    documented = _documented(doc, sections)
    missing = [p for p in required if p not in documented]
    assert not missing, f"{name}: parameters not documented: {', '.join(missing)}"
