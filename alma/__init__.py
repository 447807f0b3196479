"""alma — limit analysis of masonry block structures (rigid blocks, no-tension frictional joints)."""
from alma.geometry.contacts import Joints, find_joints
from alma.mechanics.model import Model, build_model
from alma.geometry.panels import paper_panel, wall
from alma.results.result import Bounds, Result
from alma.geometry.scene import Block, Scene, SceneError, load_scene
from alma.solve import solve

__all__ = ["Block", "Bounds", "Joints", "Model", "Result", "Scene", "SceneError", "build_model",
           "find_joints", "load_scene", "paper_panel", "solve", "wall"]
__version__ = "0.1.0"
