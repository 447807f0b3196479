"""The worker side of a study: one task is one geometry with all its chains, frictions and models."""

from __future__ import annotations

import dataclasses
import json
import math
import signal
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import alma
from alma.engine.pattern_cache import PatternCache
from alma.geometry.chains import with_chain
from alma.geometry.contacts import find_joints
from alma.geometry.panels import BLOCK_LENGTHS, PANEL_HEIGHTS
from alma.geometry.validation import validated
from alma.report.plot import MechanismPicture
from alma.settings import Settings
from alma.study.store import PICTURE

#: Relative cost of a bond's panels (measured on Table 5), to hand out the largest tasks first.
_BOND_COST = {"running": 1.0, "stack": 0.6, "english": 1.6, "flemish": 1.3}


@dataclass(frozen=True)
class _Task:
    panel_ratio: str
    block_ratio: str
    bond: str
    items: tuple[tuple[float, float, str, str], ...]  # (chain kN, friction, model, key) still to do
    version: str
    settings: Settings = Settings()
    chain_y: float = 0.0  # mm, height of the chain (Design.chain_y)
    chain_anchored: bool = False
    compressive_strength: float = 0.0  # MPa on every joint; 0: infinitely strong blocks

    @property
    def size(self) -> float:
        """Rough relative cost (LP time grows faster than the block count; measured on Table 5)."""
        n_blocks = PANEL_HEIGHTS.get(self.panel_ratio, 1.0) / 60.0 * 1440.0 / BLOCK_LENGTHS.get(self.block_ratio, 1.0)
        return n_blocks**1.7 * _BOND_COST.get(self.bond, 1.0) * len(self.items)


def _num(x: Any) -> float:
    try:
        v = float(x)
    except (TypeError, ValueError):
        return math.nan
    return v


def _row(
    task: _Task,
    item: tuple[float, float, str, str],
    *,
    result: Any = None,
    error: str = "",
    timings: dict[str, float] | None = None,
) -> dict[str, Any]:
    chain, friction, model, key = item
    row: dict[str, Any] = {
        "panel_ratio": task.panel_ratio,
        "block_ratio": task.block_ratio,
        "bond": task.bond,
        "friction": float(friction),
        "model": model,
        "alma_version": task.version,
        "key": key,
        "chain": float(chain),
        "compressive_strength": float(task.compressive_strength),
    }
    t = dict(timings or {})
    row["effort"] = "" if model == "associative" else task.settings.search.effort
    if result is not None:
        t.update({k: v for k, v in result.timings.items() if k in ("solve_s", "certify_s")})
        row.update(
            {
                "alpha_c": _num(result.alpha),
                "status": str(result.status),
                "alpha_lower": _num(result.bounds.lower),
                "alpha_upper": _num(result.bounds.upper),
                "gap": _num(result.bounds.gap),
                "mechanism_class": str(result.mechanism_class or ""),
                "message": str(getattr(result, "message", "") or ""),
            }
        )
        row.update(_comparison_fields(result, model))
        try:
            row[PICTURE] = MechanismPicture.from_result(result)
        except Exception:  # a picture is a convenience: it must not lose the result
            pass
    else:
        row.update(
            {
                "alpha_c": math.nan,
                "status": "error",
                "alpha_lower": math.nan,
                "alpha_upper": math.nan,
                "gap": math.nan,
                "mechanism_class": "",
                "message": error,
            }
        )
    for name in ("joints_s", "build_s", "solve_s", "certify_s"):
        row[name] = float(t.get(name, 0.0))
    return row


def _comparison_fields(result: Any, model: str) -> dict[str, Any]:
    """Columns of the model comparison: the associative α beside the non-associative one,
    their ratio, the winning start, the α of the start from the LP mechanism ("lp"; NaN
    when the search has no such candidate), candidate counts and the search time."""
    extra = getattr(result, "extra", None) or {}
    alpha_lp = _num(getattr(result, "alpha_associative", math.nan))
    n_blocks = extra.get("n_blocks")
    out: dict[str, Any] = {
        "alpha_associative": alpha_lp,
        "n_blocks": int(n_blocks) if isinstance(n_blocks, (int, float)) else math.nan,
    }
    if model == "associative":
        return out
    alpha = _num(result.alpha)
    ratio = alpha / alpha_lp if math.isfinite(alpha) and math.isfinite(alpha_lp) and alpha_lp > 0 else math.nan
    candidates = [c for c in extra.get("candidates") or [] if isinstance(c, dict)]
    lp = [c for c in candidates if c.get("start") == "lp"]
    out.update(
        {
            "ratio": ratio,
            "start": str(extra.get("start") or ""),
            "alpha_lp_start": _num(lp[0].get("alpha")) if lp else math.nan,
            "lp_start_verified": str(bool(lp[0].get("verified"))) if lp else "",
            "n_candidates": len(candidates),
            "n_verified": sum(bool(c.get("verified")) for c in candidates),
            "nonassociative_s": _num(result.timings.get("nonassociative_s", math.nan)),
            # [start, seconds, verified, α of its state (null if none)]
            "starts": json.dumps(
                [
                    [
                        r.get("start"),
                        round(float(r.get("time_s", math.nan)), 3),
                        bool(r.get("verified")),
                        r.get("alpha"),
                    ]  # already None when not finite (alma.result)
                    for r in extra.get("starts") or []
                    if isinstance(r, dict)
                ],
                ensure_ascii=False,
            ),
        }
    )
    return out


def _error_text(exc: BaseException) -> str:
    return f"{type(exc).__name__}: {exc}".replace("\n", " ").strip()


def _solve_task(task: _Task, emit: Callable[[dict[str, Any]], None] | None = None) -> list[dict[str, Any]]:
    """Build the geometry once and solve all (chain, friction, model) items; rows are emitted as done.

    ``joints_s`` and ``build_s`` of the geometry are charged to the first row solved from it;
    the other rows carry the (small) cost of adding the chain and of :meth:`Model.with_friction`
    as ``build_s``. Exceptions become rows with status ``error`` and the message; nothing is raised.
    """

    rows: list[dict[str, Any]] = []

    def out(row: dict[str, Any]) -> None:
        rows.append(row)
        if emit is not None:
            emit(row)

    first = {"joints_s": 0.0, "build_s": 0.0}
    try:
        t0 = time.perf_counter()
        scene = alma.paper_panel(task.bond, task.panel_ratio, task.block_ratio, task.items[0][1])
        if task.compressive_strength > 0:
            scene = dataclasses.replace(scene, compressive_strength=task.compressive_strength)
        joints = find_joints(scene)
        t1 = time.perf_counter()
        base = alma.build_model(scene, joints)
        first = {"joints_s": t1 - t0, "build_s": time.perf_counter() - t1}
    except Exception as exc:  # geometry failed: every item of the task fails with it
        for item in task.items:
            out(_row(task, item, error=_error_text(exc), timings=first))
            first = {"joints_s": 0.0, "build_s": 0.0}
        return rows

    groups: dict[tuple[float, float], list[tuple[float, float, str, str]]] = {}
    for item in task.items:
        groups.setdefault(item[:2], []).append(item)
    chained: dict[float, Any] = {0.0: base}
    patterns = PatternCache()  # the task's frictions share the interior point's patterns
    for (chain, friction), items in groups.items():
        timings = dict(first)
        try:
            t0 = time.perf_counter()
            if chain not in chained:
                chained[chain] = _chained_model(task, scene, joints, chain)
            built = chained[chain].with_friction(friction)
            timings["build_s"] += time.perf_counter() - t0
            results = _solve_models(built, tuple(item[2] for item in items), task.settings, patterns)
        except Exception as exc:
            for item in items:
                out(_row(task, item, error=_error_text(exc), timings=timings))
        else:
            for item in items:
                out(_row(task, item, result=results[item[2]], timings=timings))
        first = {"joints_s": 0.0, "build_s": 0.0}
    return rows


def _chained_model(task: _Task, scene: Any, joints: Any, strength: float) -> Any:
    """The panel's model with a chain of ``strength`` kN at ``task.chain_y`` (:func:`with_chain`).

    A chain between the end blocks leaves the blocks and joints as they are; an anchored one
    adds two fixed anchors that touch nothing, so the joints are found again.
    """
    chained, found = validated(with_chain(scene, task.chain_y, strength, anchored=task.chain_anchored, name="chain"))
    return alma.build_model(chained, found if task.chain_anchored else joints)


def _solve_models(
    built: Any, models: tuple[str, ...], settings: Settings, patterns: PatternCache | None = None
) -> dict[str, Any]:
    """Each model's result for one panel and friction, the associative LP solved once: with
    both models, one ``alma.solve(model="both")`` gives both rows."""

    if set(models) == {"associative", "nonassociative"}:
        both = alma.solve(built, model="both", settings=settings, patterns=patterns)
        return {"associative": both.associative, "nonassociative": both.nonassociative}
    return {m: alma.solve(built, model=m, settings=settings, patterns=patterns) for m in models}


# Local process pool: rows stream back through a queue given to each worker at start-up.
_WORKER_QUEUE: Any = None


def _init_worker(q: Any) -> None:
    global _WORKER_QUEUE
    _WORKER_QUEUE = q
    # Ctrl-C is handled by the parent, which stops the workers itself.
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _solve_task_pooled(task: _Task) -> list[dict[str, Any]]:
    q = _WORKER_QUEUE
    return _solve_task(task, emit=None if q is None else q.put)
