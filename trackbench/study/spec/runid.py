"""Run ids: a stable hash of the fully resolved scenario and the model version."""

import hashlib
import json

from trackbench.version import MODEL_VERSION


def run_id(scenario: dict, model_version: str = MODEL_VERSION) -> str:
    """16 hex digits of sha256(resolved scenario without its name + model version).

    The name is left out (it only labels the output), so the same physics gives the same id;
    any changed parameter, or a new model version, gives a new one."""
    d = {k: v for k, v in scenario.items() if k != "name"}
    text = json.dumps(d, sort_keys=True, separators=(",", ":")) + "|model=" + str(model_version)
    return hashlib.sha256(text.encode()).hexdigest()[:16]
