"""The assembly cell: batches of pin insertions run by mode, and campaigns of many seeds.

The compiled calls are the library's, as ``microcobot cell run`` makes them:

    b = cell.Batch(scene="scene.yaml", parts=5, seed=3)   # --scene --batch --seed
    cycles = b.run(mode="auto")                           # [CycleResult dicts], GIL released
    cell.summarize(cycles)                                # as `cell run --json`
    c = cell.Cycle(b, 0, mode="auto", task={"steps": {"insert": "confirm"}})   # a task from Python
    c.run_for(5.0); c.pause(); c.resume(); c.confirm(); c.run_to_end(); c.result()

``batch(config, seeds, client=None)`` runs the same batch for every seed, one Dask task per part:
on a local process pool by default, or on a ``dask.distributed.Client``'s cluster. The simulation
is deterministic from the seed, so the results are those of the serial run for the same seeds
(docs/cell.md, "Campaigns with Dask"; tests/python/test_cell.py compares every field).
"""

import numbers as _numbers
import os as _os

from . import platform as _platform
from ._microcobot import cell as _cell

Batch = _cell.Batch
Cycle = _cell.Cycle
modes = _cell.modes
params = _cell.params
run_params = _cell.run_params
summarize = _cell.summarize

# The keys of a campaign's config (docs/cell.md): each optional.
_CONFIG_KEYS = ("scene", "parts", "mode", "params", "platform")


def _resolved(config):
    """The config with every part complete and checked here, in the caller (a bad key fails on one
    line before anything is sent), and every file read: workers get plain dicts, so a remote worker
    needs none of the caller's files."""
    if config is None:
        config = {}
    if not isinstance(config, dict):
        raise TypeError(f"config: expected a dict (got {type(config).__name__} {config!r:.60})")
    unknown = [k for k in config if k not in _CONFIG_KEYS]
    if unknown:
        raise ValueError(f"config: unknown key {unknown[0]!r} (known: {', '.join(_CONFIG_KEYS)})")
    scene = Batch(config.get("scene"), parts=config.get("parts")).scene
    run = run_params(config.get("params"), config.get("mode"))
    return {"scene": scene, "run": run, "platform": _platform.config(config.get("platform"))}


def _seed_list(seeds):
    if isinstance(seeds, (str, bytes)) or not hasattr(seeds, "__iter__"):
        raise TypeError(f"seeds: expected a list of ints (got {type(seeds).__name__} {seeds!r:.60})")
    out = []
    for i, s in enumerate(seeds):
        if isinstance(s, bool) or not isinstance(s, _numbers.Integral):
            raise TypeError(f"seeds[{i}]: expected an int (got {type(s).__name__} {s!r:.60})")
        out.append(int(s))
    if not out:
        raise ValueError("seeds: an empty list (a campaign needs at least one seed)")
    return out


def _run_part(resolved, seed, index):
    """One task: part `index` of the batch of `seed` (module level: workers import it by name)."""
    b = Batch(resolved["scene"], seed=seed)
    return b.run_cycle(index, params=resolved["run"], config=resolved["platform"])


def batch(config, seeds, client=None, workers=None):
    """A campaign: the batch of ``config`` for every seed, each part one Dask task.

    config: a dict, every key optional (docs/cell.md): ``scene`` (None, dict of scene keys or a
    YAML file, as --scene), ``parts`` (as --batch), ``mode`` ('auto', 'manual', ... passed through
    to the run parameters), ``params`` (run parameters: dict or YAML file, as --params),
    ``platform`` (platform configuration: dict or YAML file, as --config).
    seeds: the batches' seeds (ints >= 0), in the order the results come back.
    client: None runs the tasks on a local pool of ``workers`` processes (default: one per core)
    with Dask's "processes" scheduler; a ``dask.distributed.Client`` runs them on its cluster (the
    workers must import this microcobot).
    Returns {'config': the resolved config, 'seeds', 'runs': [{'seed', 'cycles': [CycleResult
    dicts], 'summary'}], 'summary': over every cycle}; the cycles equal those of
    ``Batch(scene, seed=s).run(mode)`` for each seed, wall_s (wall-clock time) aside.
    Raises ValueError / TypeError naming a bad argument, in the caller, before any task runs.
    """
    resolved = _resolved(config)
    seed_list = _seed_list(seeds)
    for i, s in enumerate(seed_list):
        try:
            Batch(resolved["scene"], seed=s)  # each seed's batch is valid (cheap: no simulation)
        except ValueError as e:
            raise ValueError(f"seeds[{i}]: {e}") from None
    if client is not None and workers is not None:
        raise ValueError(f"workers: {workers!r} sets the local pool's size; with a client its cluster decides")
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise ValueError(f"workers: expected an int >= 1 (got {workers!r:.60})")
    if client is not None and not (hasattr(client, "compute") and hasattr(client, "gather")):
        raise TypeError(f"client: expected a dask.distributed.Client (got {type(client).__name__})")

    import dask  # only campaigns need Dask (python3-dask, python3-distributed)

    parts = resolved["scene"]["parts"]
    tasks = [dask.delayed(_run_part, pure=False)(resolved, s, i) for s in seed_list for i in range(parts)]
    if client is None:
        cycles = dask.compute(*tasks, scheduler="processes", num_workers=workers or _os.cpu_count() or 1)
    else:
        cycles = client.gather(client.compute(tasks))
    runs = []
    for k, s in enumerate(seed_list):
        mine = list(cycles[k * parts:(k + 1) * parts])
        runs.append({"seed": s, "cycles": mine, "summary": summarize(mine)})
    return {
        "config": resolved,
        "seeds": seed_list,
        "runs": runs,
        "summary": summarize([c for r in runs for c in r["cycles"]]),
    }
