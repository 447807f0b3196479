"""Incremental large-displacement analysis: the capacity curve α(d) (SPEC §3 ``alma push``)."""

from alma.push.curve import PUSH_MODELS, push
from alma.push.result import PushPoint, PushResult

__all__ = ["PUSH_MODELS", "PushPoint", "PushResult", "push"]
