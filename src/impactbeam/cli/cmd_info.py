"""``impactbeam info``: versions of impactbeam, Python and the main dependencies."""

from __future__ import annotations

import click

from ._group import handle_errors

__all__ = ["info"]


_INFO_PACKAGES = ("numpy", "scipy", "xarray", "dask", "matplotlib", "pint")


@click.command()
@handle_errors
def info() -> None:
    """Versions of impactbeam, Python and the main dependencies."""
    import platform
    from importlib.metadata import PackageNotFoundError, version

    def ver(name: str) -> str:
        try:
            return version(name)
        except PackageNotFoundError:
            return "not installed"

    rows = [("impactbeam", ver("impactbeam")), ("python", platform.python_version())]
    rows += [(name, ver(name)) for name in _INFO_PACKAGES]
    width = max(len(n) for n, _ in rows)
    for name, v in rows:
        click.echo(f"{name.ljust(width)}  {v}")
