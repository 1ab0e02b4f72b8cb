"""SpherePlateImpact: its interface table (variables.py)."""
