"""Pictures of mechanisms: macro-blocks outlined, the crack drawn, rotation centres marked (issue 19)."""
from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402

import alma  # noqa: E402
from alma.report.plot import plot_mechanism  # noqa: E402


def _column(n: int = 3) -> alma.Scene:
    """A column of ``n`` 100 × 300 mm blocks on the ground: it rocks as one macro-block about the
    ground's right corner (α = b / h of the whole column)."""
    blocks = [alma.Block("ground", np.array([[-200, -50], [300, -50], [300, 0], [-200, 0]], float), fixed=True)]
    blocks += [alma.Block(f"b{k}", np.array([[0, 300 * k], [100, 300 * k], [100, 300 * (k + 1)], [0, 300 * (k + 1)]],
                                            float)) for k in range(n)]
    return alma.Scene(blocks=tuple(blocks), friction=2.0)


def _drawn(scene: alma.Scene, result, tmp_path, **options):
    fig, ax = plt.subplots()
    plot_mechanism(scene, result, tmp_path / "m.png", ax=ax, **options)
    return fig, ax


def test_a_rocking_column_is_one_outlined_body_with_a_hinge_on_the_crack(tmp_path):
    scene = _column()
    result = alma.solve(scene)
    assert result.alpha == np.float64(result.alpha) and abs(result.alpha - 100 / 900) < 1e-9
    assert len(result.macro_blocks) == 1 and result.macro_blocks[0].motion == "rotation"
    fig, ax = _drawn(scene, result, tmp_path)
    cracks = [c for c in ax.collections if isinstance(c, LineCollection) and np.max(c.get_linewidths()) > 2]
    assert len(cracks) == 1 and len(cracks[0].get_segments()) == 1  # the base joint, one line
    segment = cracks[0].get_segments()[0]
    hinge_end = segment[np.argmax(segment[:, 0])]
    assert np.allclose(hinge_end, (100.0, 0.0), atol=1e-6)  # the base joint, drawn midway: fixed at the hinge
    assert segment[np.argmin(segment[:, 0]), 1] > 0  # and open at the heel
    hinges = [line for line in ax.lines if line.get_marker() == "o"]
    assert len(hinges) == 1 and np.allclose(hinges[0].get_xydata()[0], (100.0, 0.0), atol=1e-6)
    plt.close(fig)


def test_macro_blocks_can_be_left_out_and_single_blocks_keep_their_outline(tmp_path):
    scene = _column(1)
    result = alma.solve(scene)
    fig, ax = _drawn(scene, result, tmp_path, macro_blocks=False)
    assert not [line for line in ax.lines if line.get_marker() in ("o", "x")]
    plt.close(fig)
    fig, ax = _drawn(scene, result, tmp_path)
    marks = [line for line in ax.lines if line.get_marker() in ("o", "x") or line.get_linestyle() == "-"]
    assert len(marks) == 1 and marks[0].get_marker() == "o"  # the hinge only: no outline of a single block
    plt.close(fig)


def test_the_line_of_thrust_passes_the_hinge(tmp_path):
    scene = _column(1)
    fig, ax = _drawn(scene, alma.solve(scene), tmp_path)
    centres = [line for line in ax.lines if line.get_marker() == "."]
    assert len(centres) == 1 and np.allclose(centres[0].get_xydata(), [(100.0, 0.0)], atol=1e-6)
    plt.close(fig)


def test_a_kept_picture_without_forces_draws_without_a_line_of_thrust(tmp_path):
    from alma.report.plot import MechanismPicture

    scene = _column(2)
    picture = MechanismPicture.from_result(alma.solve(scene))
    fig, ax = _drawn(scene, picture, tmp_path)
    assert not [line for line in ax.lines if line.get_marker() == "."]
    plt.close(fig)
