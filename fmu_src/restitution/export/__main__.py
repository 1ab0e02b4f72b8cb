"""``python -m restitution.export`` runs ``restitution export``."""
import sys

from .command import main

if __name__ == "__main__":
    sys.exit(main())
