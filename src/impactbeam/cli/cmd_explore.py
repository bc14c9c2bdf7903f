"""``impactbeam explore``: the live explorer in the browser (the ``explore`` extra)."""

from __future__ import annotations

import click

from ..exceptions import ParameterError
from ._group import handle_errors

__all__ = ["explore"]


def _check_port(port: int) -> None:
    """ParameterError naming --port when 127.0.0.1:port cannot be listened on (in use, not allowed)."""
    import socket

    if port == 0:  # any free port
        return
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
        try:
            sock.bind(("127.0.0.1", port))
        except OSError as exc:
            raise ParameterError(f"--port: cannot serve on 127.0.0.1:{port}: {exc.strerror or exc} "
                                 "(another server uses it?); choose another port") from None


@click.command("explore")
@click.argument("scenario", metavar="[SCENARIO]", required=False)
@click.option("--port", "port", type=click.IntRange(0, 65535), default=5006, show_default=True, metavar="N",
              help="Port on 127.0.0.1 to serve on.")
@click.option("--show/--no-show", "show", default=False, show_default=True, help="Open a browser tab.")
@handle_errors
def explore(scenario: str | None, port: int, show: bool) -> None:
    """Explore SCENARIO live: sliders for gap, contact stiffness and position, pulse
    amplitude and duration, damping and modes; the response, contact force and
    metrics redraw on every change, and a button saves the scenario as TOML.

    Without SCENARIO, the paper's reference case (Table 1, Case 3) is used.
    Serves on http://127.0.0.1:N until interrupted (Ctrl-C).
    """
    from .._optional import require

    _check_port(port)
    require("panel", "explore", feature="impactbeam explore")
    from ..explore import serve

    if scenario is None:
        from ..paper import case

        sc = case(3, source="parameters")
    else:
        from ._group import load_with_overrides

        sc = load_with_overrides(scenario)
    serve(sc, port=port, show=show, announce=lambda text: click.echo(text, err=True))
