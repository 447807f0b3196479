"""The command line (SPEC §3): ``alma solve|panel|wall|arch|tilt|settle|doe|anova|paper|compare``."""

from alma.cli.main import main

__all__ = ["main"]
