"""alma — limit analysis of masonry block structures (rigid blocks, no-tension frictional joints)."""
from .contacts import Joints, find_joints
from .model import Model, build_model
from .panels import paper_panel, wall
from .result import Bounds, Result
from .scene import Block, Scene, SceneError, load_scene
from .solve import solve

__all__ = ["Block", "Bounds", "Joints", "Model", "Result", "Scene", "SceneError", "build_model",
           "find_joints", "load_scene", "paper_panel", "solve", "wall"]
__version__ = "0.1.0"
