"""``python -m impactbeam.cli``: the command line."""

from . import console_main

if __name__ == "__main__":  # pragma: no branch
    console_main()
