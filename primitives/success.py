"""``python -m primitives.success``: the success models command line, kept at this name; the machinery is
:mod:`primitives.training.success`."""

from primitives.training.success import main

if __name__ == "__main__":
    raise SystemExit(main())
