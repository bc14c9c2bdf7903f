"""``python -m impactbeam``: the same command line as the ``impactbeam`` script."""

from .cli import console_main

if __name__ == "__main__":  # pragma: no branch
    console_main()
