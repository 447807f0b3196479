"""The package's version, read from its installed metadata.

setuptools-scm writes it from git when the package is built or installed
(``[tool.setuptools_scm]`` in pyproject.toml): ``X.Y.Z`` on a tagged commit, ``X.Y.(Z+1).devN``
N commits after the tag.  An editable install keeps the version of its last ``pip install``.
"""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__: str = version("alma")
except PackageNotFoundError:  # a source tree on sys.path that was never installed
    __version__ = "0.0.0+unknown"
