"""``python -m impactbeam``: the same command line as the ``impactbeam`` script."""

from .cli import main

if __name__ == "__main__":  # pragma: no branch
    main(prog_name="impactbeam")
