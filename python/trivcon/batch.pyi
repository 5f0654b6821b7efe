# SPDX-License-Identifier: MIT
# Type stubs of trivcon.batch (python/trivcon/batch.py; see its docstrings).
from typing import Any, Dict, List, Optional, Sequence, TextIO, Tuple

__all__: List[str]

MESH_SUFFIXES: Tuple[str, ...]
FIELD_FORMATS: Tuple[str, ...]
COLUMNS: Tuple[str, ...]
STATUSES: Tuple[str, ...]

class UsageError(Exception): ...

def mesh_name(path: str) -> str: ...
def find_meshes(paths: Sequence[str]) -> List[str]: ...
def solve_mesh(job: Dict[str, Any]) -> Dict[str, Any]: ...

class Progress:
    total: int
    done: int
    failed: int
    not_ok: int
    def __init__(self, total: int, stream: Optional[TextIO] = ..., width: int = ...) -> None: ...
    def line(self, last: str = ...) -> str: ...
    def update(self, row: Dict[str, Any]) -> None: ...

def format_table(rows: Sequence[Dict[str, Any]]) -> str: ...
def run(
    meshes: Sequence[str],
    out: str,
    N: int = ...,
    sing_dir: Optional[str] = ...,
    auto_cancel: float = ...,
    align_boundary: bool = ...,
    weights: str = ...,
    field_format: str = ...,
    connection: bool = ...,
    png: bool = ...,
    scheduler: Optional[str] = ...,
    workers: Optional[int] = ...,
    threads_per_worker: int = ...,
    progress: bool = ...,
    stream: Optional[TextIO] = ...,
    timeout: float = ...,
    split_large_turns: bool = ...,
    threads: Optional[int] = ...,
    repair: bool = ...,
) -> List[Dict[str, Any]]: ...
def main(argv: Optional[Sequence[str]] = ...) -> int: ...
