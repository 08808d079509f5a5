"""Type stub of the compiled extension (python/src/lib.rs)."""

from typing import List, Optional, Tuple

def run_json(args: List[str]) -> Tuple[int, str]:
    """Runs ``eigenfit ARGS… --json``; ``(0 or 3, JSON text)`` or ``(1 or 2, error message)``."""

def version() -> str:
    """Version of the Rust crates the extension was built from."""

def options(command: str) -> Optional[List[str]]:
    """The long options of ``eigenfit COMMAND`` without the dashes (``max-iterations``), or None."""
