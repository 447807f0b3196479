"""alma — limit analysis of masonry block structures (rigid blocks, no-tension frictional joints).

Data flows one way: ``geometry`` (scenes, joints, panels) → ``mechanics`` (the sparse model of
Eqs. 1–8) → ``backends`` and the solvers (``associative``, ``nonassociative``, ``certify``) →
``results`` → ``study``, ``report``, ``paper`` → ``cli``.  See docs/architecture.md.
"""

from alma.geometry.contacts import Joints, find_joints
from alma.geometry.generators import arch, coursed_wall, facade, wall
from alma.geometry.panels import paper_panel
from alma.geometry.scene import Block, Scene, SceneError, load_scene
from alma.mechanics.model import Model, build_model
from alma.push import PushResult, push
from alma.push.settlement import SettlementCapacity, settlement_capacity
from alma.results.types import AssociativeResult, Bounds, Comparison, NonAssociativeResult, Result
from alma.seismic import SeismicResult, Site, load_site, seismic
from alma.settings import (
    AssociativeSettings,
    CertifySettings,
    IPMSettings,
    PushSettings,
    SearchSettings,
    Settings,
    StateTolerances,
)
from alma.settle import SettlementResult, settle
from alma.solve import solve
from alma.status import Status
from alma.tilt import TiltResult, TiltSettings, tilt

__all__ = [
    "AssociativeResult",
    "AssociativeSettings",
    "Block",
    "Bounds",
    "CertifySettings",
    "Comparison",
    "IPMSettings",
    "Joints",
    "Model",
    "NonAssociativeResult",
    "PushResult",
    "PushSettings",
    "Result",
    "Scene",
    "SceneError",
    "SearchSettings",
    "SeismicResult",
    "Settings",
    "SettlementCapacity",
    "SettlementResult",
    "Site",
    "StateTolerances",
    "Status",
    "TiltResult",
    "TiltSettings",
    "arch",
    "build_model",
    "coursed_wall",
    "facade",
    "find_joints",
    "load_scene",
    "load_site",
    "paper_panel",
    "push",
    "seismic",
    "settle",
    "settlement_capacity",
    "solve",
    "tilt",
    "wall",
]
from alma._version import __version__ as __version__  # from git (setuptools-scm)
