"""camtool: CAD/CAM for small, home-built and legacy CNC machines.

The public API (docs/api.md): read a drawing, plan it, post it for a target,
verify the code by simulating it on the target's machine::

Design notes: docs/internals.md, ``camtool/__init__.py``.
"""

from __future__ import annotations

from importlib import import_module
from typing import TYPE_CHECKING, Any

from camtool.model.version import __version__

_HOMES: dict[str, str] = {
    # the model: shapes and programs in mm, machines, errors
    "Drawing": "camtool.model.shapes",
    "Contour": "camtool.model.shapes",
    "Line": "camtool.model.shapes",
    "Arc": "camtool.model.shapes",
    "Program": "camtool.model.program",
    "Rapid": "camtool.model.program",
    "Linear": "camtool.model.program",
    "ArcMove": "camtool.model.program",
    "Machine": "camtool.model.machine",
    "CamtoolError": "camtool.model.errors",
    "UsageError": "camtool.model.errors",
    "InputError": "camtool.model.errors",
    "ParseError": "camtool.model.errors",
    "ToolpathError": "camtool.model.errors",
    "DialectError": "camtool.model.errors",
    "VerifyLimitError": "camtool.model.errors",
    # read
    "read_drawing": "camtool.importers",
    "ImportOptions": "camtool.importers.options",
    # plan
    "PlanOptions": "camtool.toolpath.options",
    "plan_drawing": "camtool.toolpath.plan",
    "Plan": "camtool.toolpath.plan",
    "PlanReport": "camtool.toolpath.plan",
    # targets
    "Target": "camtool.post.base",
    "load_target": "camtool.post.registry",
    "list_targets": "camtool.post.registry",
    # jobs: operations and tools, run as one program
    "Job": "camtool.jobs.job",
    "Tool": "camtool.jobs.job",
    "Operation": "camtool.jobs.job",
    "Selection": "camtool.jobs.job",
    "load_job": "camtool.jobs.jobfile",
    "run_job": "camtool.jobs.run",
    # post
    "OutputOptions": "camtool.jobs.run",
    "PostJob": "camtool.jobs.run",
    "plan_options": "camtool.jobs.run",
    "post_drawing": "camtool.jobs.pipeline",
    "post_path": "camtool.jobs.pipeline",
    "post_file": "camtool.jobs.pipeline",
    "post_program": "camtool.jobs.pipeline",
    "verify_job": "camtool.jobs.pipeline",
    # many files, several targets, a process pool or a Dask cluster: camtool.batch.run(...)
    "batch": "camtool.jobs",
    # verify
    "Verification": "camtool.verify.verifier",
    "verify_code": "camtool.verify.verifier",
    "verify_program": "camtool.verify.verifier",
}
"""Each public name → the module that defines it (or the package of a public submodule)."""

__all__ = ["__version__", *_HOMES]
"""The public API: each name is defined in the module :data:`_HOMES` gives."""


def __getattr__(name: str) -> Any:
    """The public ``name``, imported from its module on first use (PEP 562).

    A name whose home is a package and that is none of its attributes is its
    submodule: ``camtool.batch`` is the module :mod:`camtool.jobs.batch`.

    Raises:
        AttributeError: ``name`` is not public (nor a submodule already imported).
    """
    home = _HOMES.get(name)
    if home is None:
        raise AttributeError(f"module 'camtool' has no attribute {name!r}")
    module = import_module(home)
    value = getattr(module, name, None)
    if value is None:
        value = import_module(f"{home}.{name}")
    globals()[name] = value  # the next lookup is an ordinary attribute
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_HOMES})


if TYPE_CHECKING:  # the names as type checkers see them (``X as X``: exported, PEP 484)
    from camtool.importers import read_drawing as read_drawing
    from camtool.importers.options import ImportOptions as ImportOptions
    from camtool.jobs import batch as batch
    from camtool.jobs.job import Job as Job
    from camtool.jobs.job import Operation as Operation
    from camtool.jobs.job import Selection as Selection
    from camtool.jobs.job import Tool as Tool
    from camtool.jobs.jobfile import load_job as load_job
    from camtool.jobs.pipeline import post_drawing as post_drawing
    from camtool.jobs.pipeline import post_file as post_file
    from camtool.jobs.pipeline import post_path as post_path
    from camtool.jobs.pipeline import post_program as post_program
    from camtool.jobs.pipeline import verify_job as verify_job
    from camtool.jobs.run import OutputOptions as OutputOptions
    from camtool.jobs.run import PostJob as PostJob
    from camtool.jobs.run import plan_options as plan_options
    from camtool.jobs.run import run_job as run_job
    from camtool.model.errors import CamtoolError as CamtoolError
    from camtool.model.errors import DialectError as DialectError
    from camtool.model.errors import InputError as InputError
    from camtool.model.errors import ParseError as ParseError
    from camtool.model.errors import ToolpathError as ToolpathError
    from camtool.model.errors import UsageError as UsageError
    from camtool.model.errors import VerifyLimitError as VerifyLimitError
    from camtool.model.machine import Machine as Machine
    from camtool.model.program import ArcMove as ArcMove
    from camtool.model.program import Linear as Linear
    from camtool.model.program import Program as Program
    from camtool.model.program import Rapid as Rapid
    from camtool.model.shapes import Arc as Arc
    from camtool.model.shapes import Contour as Contour
    from camtool.model.shapes import Drawing as Drawing
    from camtool.model.shapes import Line as Line
    from camtool.post.base import Target as Target
    from camtool.post.registry import list_targets as list_targets
    from camtool.post.registry import load_target as load_target
    from camtool.toolpath.options import PlanOptions as PlanOptions
    from camtool.toolpath.plan import Plan as Plan
    from camtool.toolpath.plan import PlanReport as PlanReport
    from camtool.toolpath.plan import plan_drawing as plan_drawing
    from camtool.verify.verifier import Verification as Verification
    from camtool.verify.verifier import verify_code as verify_code
    from camtool.verify.verifier import verify_program as verify_program
