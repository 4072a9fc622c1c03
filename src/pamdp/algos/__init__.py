"""Learning algorithms for parameterized action spaces, sharing one API (see ``base.py``)."""
