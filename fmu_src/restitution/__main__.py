"""``python -m restitution``: the ``restitution`` command (:mod:`restitution.command`)."""
import sys

from .command import main

sys.exit(main())
