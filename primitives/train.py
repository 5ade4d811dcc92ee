"""``python -m primitives.train``: the training command line, kept at this name; the machinery is
:mod:`primitives.training.train`."""

from primitives.training.train import main

if __name__ == "__main__":
    raise SystemExit(main())
