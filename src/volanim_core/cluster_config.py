"""A Dask cluster started from a file: the cluster spec dask-ctl reads, so one file serves both tools.

    cluster.yaml (version 1: module, class, args, kwargs)
      --read_cluster_spec-->  ClusterSpec, checked: each key's type, the module importable, the class in it
      --started_cluster-->    the class called with args and kwargs (dask-jobqueue's SLURMCluster, dask-kubernetes'
                              KubeCluster, distributed's LocalCluster, ...), a Client on it, its dashboard said;
                              on leaving, the client and the cluster closed (jobqueue cancels its jobs)

The cluster itself is Dask's own deployment tool; only reading the file is ours, so that a bad one says
which file, which key and what to write (dask-ctl raises a bare KeyError). ``dask cluster create -f FILE``
(dask-ctl) starts the same cluster by hand. See docs/tutorials/cluster.md.
"""

from __future__ import annotations

import importlib
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

from volanim_core.errors import FormatError

EXAMPLE = "version: 1\nmodule: dask_jobqueue\nclass: SLURMCluster\nkwargs:\n  cores: 2\n  memory: 6GB\n  n_workers: 4"
INSTALL = {"dask_jobqueue": "dask-jobqueue", "dask_kubernetes": "dask-kubernetes"}


@dataclass(frozen=True)
class ClusterSpec:
    """What a cluster file says: call ``module.cls(*args, **kwargs)``."""

    path: str
    module: str
    cls: str
    args: list = field(default_factory=list)
    kwargs: dict = field(default_factory=dict)

    def cluster_class(self):
        """The class the file names, imported; a module not installed or a class not in it says which."""
        top = self.module.split(".")[0]
        try:
            module = importlib.import_module(self.module)
        except ImportError as exc:
            raise FormatError(self.path, f"module {self.module!r} cannot be imported ({exc}); install it where "
                              f"volanim runs: pip install {INSTALL.get(top, top)}") from exc
        cls = getattr(module, self.cls, None)
        if not callable(cls):
            raise FormatError(self.path, f"module {self.module} has no class {self.cls!r}")
        return cls


def read_cluster_spec(path: str | Path) -> ClusterSpec:
    """The cluster spec in ``path`` (YAML), each key checked; a bad file is a FormatError naming what is wrong."""
    import yaml

    try:
        text = Path(path).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise FormatError(path, f"cannot read the cluster file: {exc}") from exc
    try:
        spec = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark, start = getattr(exc, "problem_mark", None), getattr(exc, "context_mark", None)
        opened = f" ({exc.context} at line {start.line + 1})" if start is not None and exc.context else ""
        raise FormatError(path, f"not YAML: {getattr(exc, 'problem', None) or exc}{opened}",
                          None if mark is None else mark.line + 1) from exc
    if not isinstance(spec, dict):
        raise FormatError(path, f"a cluster file is a YAML mapping, like\n{EXAMPLE}")
    if spec.get("version") != 1:
        raise FormatError(path, f"'version' is {spec.get('version')!r}: volanim reads version 1 (dask-ctl's), "
                          f"like\n{EXAMPLE}")
    unknown = sorted(set(spec) - {"version", "module", "class", "args", "kwargs"})
    if unknown:
        raise FormatError(path, f"unknown key(s) {', '.join(map(str, unknown))}: a cluster file has version, "
                          "module, class, args and kwargs (the cluster's options go under kwargs)")
    for key, kind, what in (("module", str, "a Python module, e.g. dask_jobqueue"),
                            ("class", str, "a class of that module, e.g. SLURMCluster"),
                            ("args", list, "a list"), ("kwargs", dict, "a mapping of the class's options")):
        if key in spec and not isinstance(spec[key], kind) or key in ("module", "class") and not spec.get(key):
            raise FormatError(path, f"'{key}' must be {what}, got {spec.get(key)!r}")
    return ClusterSpec(str(path), spec["module"], spec["class"], spec.get("args") or [], spec.get("kwargs") or {})


@contextmanager
def started_cluster(path: str | Path, say=print):
    """A ``distributed.Client`` on the cluster ``path`` describes, started here and closed on leaving; ``say``
    is told the cluster and its dashboard (where one is served) before any work is sent."""
    from distributed import Client

    spec = read_cluster_spec(path)
    cls = spec.cluster_class()
    try:
        cluster = cls(*spec.args, **spec.kwargs)
    except Exception as exc:  # noqa: BLE001 -- whatever the class raises, said with the file that asked for it
        refused = _type_error(exc)  # an option the class (or LocalCluster's nanny: "failed to start") does not take
        if refused is not None:
            raise FormatError(path, f"{spec.module}.{spec.cls} refused its kwargs: {refused}") from exc
        raise ConnectionError(f"{path}: {spec.module}.{spec.cls} could not start: {exc}") from exc
    with cluster, Client(cluster) as client:
        say(f"started {spec.cls} from {path}" + dashboard(client))
        yield client


def _type_error(exc: BaseException | None) -> TypeError | None:
    """The TypeError ``exc`` is or was raised from (its cause or context), if any."""
    seen = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, TypeError):
            return exc
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return None


def dashboard(client) -> str:
    """``"; dashboard http://..."`` when the scheduler serves one (bokeh installed there), else ``""``."""
    served = "dashboard" in client.scheduler_info().get("services", {})
    return f"; dashboard {client.dashboard_link}" if served else ""
