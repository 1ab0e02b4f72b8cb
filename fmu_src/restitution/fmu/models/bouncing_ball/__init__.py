"""BouncingBall: its interface table (variables.py)."""
