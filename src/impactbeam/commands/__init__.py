"""Subcommands of ``impactbeam`` that live beside their API modules.

Each module here exposes ``COMMANDS``, a list of click commands; :func:`register`
adds them to the main group. Modules import their heavy dependencies inside
the commands so ``impactbeam --help`` stays fast.
"""

from __future__ import annotations

import importlib

import click

_MODULES = ("reproduce", "sweep", "measure", "explore")


def register(main: click.Group) -> None:
    """Add every available subcommand module's ``COMMANDS`` to ``main``."""
    for name in _MODULES:
        try:
            mod = importlib.import_module(f"{__name__}.{name}")
        except ModuleNotFoundError as exc:  # a module not written yet
            if exc.name != f"{__name__}.{name}":
                raise
            continue
        for cmd in getattr(mod, "COMMANDS", ()):
            main.add_command(cmd)
