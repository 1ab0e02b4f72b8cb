"""``python -m restitution``: the ``restitution`` command (:mod:`restitution.command`)."""
import sys

from .command import main

if __name__ == "__main__":  # also imported by tools that load every module of the package
    sys.exit(main())
