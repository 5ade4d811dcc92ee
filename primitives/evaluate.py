"""``python -m primitives.evaluate``: the evaluation command line, kept at this name; the machinery is
:mod:`primitives.training.evaluate`."""

from primitives.training.evaluate import main

if __name__ == "__main__":
    raise SystemExit(main())
