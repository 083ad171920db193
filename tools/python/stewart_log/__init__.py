"""LCM logs of the stewart stack as pandas tables, one per channel
(docs/operations.md, "Logs in Python").

    import stewart_log
    tables = stewart_log.read_log("runs/<run>/log.lcm")
"""
from .lcm_types import load_types
from .logfile import read_events
from .reader import read_log

__all__ = ["read_log", "read_events", "load_types"]
