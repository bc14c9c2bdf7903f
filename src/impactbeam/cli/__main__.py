"""``python -m impactbeam.cli``: the command line."""

from . import main

if __name__ == "__main__":  # pragma: no branch
    main(prog_name="impactbeam")
