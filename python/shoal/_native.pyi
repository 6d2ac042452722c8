"""Type stubs of the native module ``shoal._native`` (built from ``python/src/``)."""

from typing import Any, Dict, List, Optional, Sequence, Tuple

class LoadError(ValueError):
    """A scenario, species, sweep file or setting did not load (located diagnostics)."""

def engine_version() -> str: ...
def run_scenario(
    scenario: str,
    seed: Optional[int] = None,
    duration: Optional[float] = None,
    set: Sequence[Tuple[str, str]] = ...,
    record_interval: Optional[int] = None,
    threads: Optional[int] = None,
) -> Dict[str, Any]: ...
