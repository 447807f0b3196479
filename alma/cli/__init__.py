"""The command line (SPEC §3): ``alma solve|panel|doe|anova|paper|compare``."""
from alma.cli.main import main

__all__ = ["main"]
