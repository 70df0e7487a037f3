"""The JSON format: a result's data (its ``to_json``: exact values as strings in the tableau
grammar, so that they re-parse exactly) serialised; the document model is for people.

>>> render({"order": 4, "B": "1/2", "name": "Störmer"})
'{"order": 4, "B": "1/2", "name": "Störmer"}'
"""
from __future__ import annotations

import json

__all__ = ["render"]


def render(data: dict[str, object]) -> str:
    """``data`` as one line of JSON, non-ASCII kept."""
    return json.dumps(data, ensure_ascii=False)
