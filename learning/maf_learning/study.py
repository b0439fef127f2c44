"""The optuna study of learning/tune: storage, workers (one process per core), trials, resumption and the report."""
import concurrent.futures
import multiprocessing
import os
import re
import shutil
import socket
import sys
import time
import warnings

import optuna
import yaml
from optuna.trial import TrialState

from . import drives as drv
from . import objective as obj
from . import runner
from . import space as sp
from .drives import PACKAGE_ROOT

DEFAULT_STUDY = "map_aided_fusion"
PRUNER_STARTUP_TRIALS = 6   # trials before any pruning
PRUNER_WARMUP_STEPS = 1     # drives a trial always finishes before it can be pruned
MAX_CONSECUTIVE_FAILURES = 5
POLL_SECONDS = 2.0


class TuneError(RuntimeError):
    """A one-line error of the tuner (storage, drives, search space): the message names the item."""


class TrialFailed(RuntimeError):
    """evaluate crashed or timed out in a trial: optuna records the trial as failed, never as a score."""


def redact(url):
    return re.sub(r"(://[^:/@]+):[^@]*@", r"\1:***@", url)


def open_storage(url):
    """An optuna storage: journal:PATH (default, a local file), sqlite:///PATH or postgresql://..."""
    try:
        if url.startswith("journal:"):
            path = url[len("journal:"):]
            os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
            return optuna.storages.JournalStorage(optuna.storages.JournalFileStorage(path))
        if url.startswith("sqlite:///"):
            os.makedirs(os.path.dirname(os.path.abspath(url[len("sqlite:///"):])), exist_ok=True)
            return optuna.storages.RDBStorage(url)
        if url.startswith(("postgresql://", "postgresql+psycopg2://")):
            return optuna.storages.RDBStorage(url, engine_kwargs={"connect_args": {"connect_timeout": 5}},
                                              heartbeat_interval=30, grace_period=120)
    except Exception as e:  # noqa: BLE001 - any driver error is the storage's
        msg = [ln for ln in str(e).splitlines() if ln.strip()]
        raise TuneError(f"storage {redact(url)}: cannot open it: {msg[0] if msg else type(e).__name__}")
    raise TuneError(f"storage {redact(url)}: unknown kind (journal:PATH, sqlite:///PATH or "
                    "postgresql://USER[:PASSWORD]@HOST:PORT/DATABASE)")


class Setup:
    """What every worker needs: the training drives, the search space, the tools, the reference scores."""

    def __init__(self, args):
        self.args = args
        self.work = os.path.abspath(args.work)
        self.config = os.path.abspath(args.config)
        try:
            self.drive_set = drv.load_drive_set(args.drives)
        except (drv.DriveError, OSError) as e:
            raise TuneError(str(e))
        self.storage_url = args.storage or "journal:" + os.path.join(self.work, f"{args.study}.journal")
        try:
            self.params = sp.load_space(args.space, self.config)
        except sp.SpaceError as e:
            raise TuneError(str(e))
        try:
            self.evaluate = args.evaluate or runner.tool("evaluate")
            self.simulate = runner.tool("simulate")
        except runner.EvaluationError as e:
            raise TuneError(str(e))
        self.road_maps = {}
        try:
            self.training = [runner.Drive(d, self.work, self.road_maps) for d in self.drive_set["training"]]
        except (drv.DriveError, OSError) as e:
            raise TuneError(str(e))
        if not self.training:
            raise TuneError(f"drive set {args.drives}: no training drive")

    def held_out(self):
        return [runner.Drive(d, self.work, self.road_maps) for d in self.drive_set["held_out"]]

    def prepare(self, drives_list, log=print):
        for d in drives_list:
            t0 = time.time()
            try:
                if d.prepare(self.simulate):
                    log(f"simulated {d.name} ({d.preset}) in {time.time() - t0:.0f} s")
            except runner.EvaluationError as e:
                raise TuneError(str(e))


def _counted(trials):
    return sum(1 for t in trials if t.state in (TrialState.COMPLETE, TrialState.PRUNED, TrialState.RUNNING) or
               (t.state == TrialState.FAIL and not t.user_attrs.get("interrupted")))


def _pid_alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def fail_interrupted(study, storage):
    """Trials left RUNNING by a worker of this machine that no longer runs become FAIL (interrupted)."""
    host = socket.gethostname()
    n = 0
    for t in study.get_trials(deepcopy=False, states=(TrialState.RUNNING,)):
        worker = t.user_attrs.get("worker", "")
        w_host, _, w_pid = worker.rpartition(":")
        if w_host == host and w_pid.isdigit() and not _pid_alive(int(w_pid)):
            storage.set_trial_user_attr(t._trial_id, "interrupted", True)
            storage.set_trial_state_values(t._trial_id, state=TrialState.FAIL)
            n += 1
    return n


def reference_scores(setup, log=print):
    """The paper's parameters on the training drives, pooled over the first k drives for k = 1..n."""
    paper_dir = os.path.join(setup.config, "paper")
    metrics, prefixes = [], []
    for d in setup.training:
        try:
            metrics.append(d.evaluate(setup.evaluate, paper_dir, "paper", setup.args.trial_timeout))
        except runner.EvaluationError as e:
            raise TuneError(f"reference (paper) run: {e}")
        prefixes.append(obj.pool(metrics))
    log("reference (paper's parameters) on the training drives: " + _summary(prefixes[-1]))
    return prefixes


def _summary(p):
    return (f"mean IoU {p['mean_iou']:.3f}, V precision {p['v_precision']:.3f}, V recall {p['v_recall']:.3f}, "
            f"detected {p['moving_detected']}/{p['moving_visible']}, trail {p['trail']:.1f}")


def create_or_load(setup, log=print):
    storage = open_storage(setup.storage_url)
    names = [d.name for d in setup.training]
    space_desc = {p.key: p.describe() for p in setup.params}
    try:
        study = optuna.create_study(study_name=setup.args.study, storage=storage, direction="maximize",
                                    load_if_exists=True)
    except Exception as e:  # noqa: BLE001
        raise TuneError(f"storage {redact(setup.storage_url)}: {str(e).splitlines()[0] if str(e) else e}")
    attrs = study.user_attrs
    if "training_drives" in attrs:
        if attrs["training_drives"] != names:
            raise TuneError(f"study '{setup.args.study}' was made on the drives {', '.join(attrs['training_drives'])}, "
                            f"not {', '.join(names)}: use another --study")
        if attrs.get("space") != space_desc:
            raise TuneError(f"study '{setup.args.study}' was made with another search space: use another --study")
    else:
        study.set_user_attr("training_drives", names)
        study.set_user_attr("space", space_desc)
        study.set_user_attr("objective", obj.__doc__.strip().splitlines()[0])
        base = sp.base_values(setup.config)
        study.enqueue_trial({p.key: base[p.file][p.name] for p in setup.params}, user_attrs={"seeded": "config/"})
    if "reference" not in study.user_attrs:
        setup.prepare(setup.training, log)
        study.set_user_attr("reference", reference_scores(setup, log))
    return study, storage


def _objective(setup, reference):
    params, host, pid = setup.params, socket.gethostname(), os.getpid()

    def run(trial):
        trial.set_user_attr("worker", f"{host}:{pid}")
        values = {p.key: p.suggest(trial) for p in params}
        config_dir = os.path.join(setup.work, "trials", f"{trial.number:05d}")
        by_file = sp.split_values(values)
        for name in ("fusion.yaml", "scan_grid.yaml"):
            by_file.setdefault(name, {}).setdefault("threads", 1)  # one worker per core already
        sp.write_config_dir(config_dir, by_file, setup.config)
        metrics = []
        try:
            for k, d in enumerate(setup.training):
                try:
                    metrics.append(d.evaluate(setup.evaluate, config_dir, "default", setup.args.trial_timeout))
                except runner.EvaluationError as e:
                    trial.set_user_attr("failure", str(e))
                    raise TrialFailed(str(e))
                value = obj.score(obj.pool(metrics), reference[k])
                trial.report(value, k)
                if k + 1 < len(setup.training) and trial.should_prune():
                    raise optuna.TrialPruned()
        finally:
            shutil.rmtree(config_dir, ignore_errors=True)
        pooled = obj.pool(metrics)
        trial.set_user_attr("scores", pooled)
        return obj.score(pooled, reference[-1])

    return run


def worker(setup, index, target):
    """One worker process: trials until the study holds `target` counted trials."""
    optuna.logging.set_verbosity(optuna.logging.ERROR)
    warnings.filterwarnings("ignore", message=".*experimental.*")
    storage = open_storage(setup.storage_url)
    sampler = optuna.samplers.TPESampler(seed=None if setup.args.seed is None else setup.args.seed + index,
                                         n_startup_trials=setup.args.startup_trials)
    pruner = optuna.pruners.MedianPruner(n_startup_trials=PRUNER_STARTUP_TRIALS, n_warmup_steps=PRUNER_WARMUP_STEPS)
    study = optuna.load_study(study_name=setup.args.study, storage=storage, sampler=sampler, pruner=pruner)
    reference = study.user_attrs["reference"]
    run = _objective(setup, reference)
    failures = 0
    while _counted(study.get_trials(deepcopy=False)) < target:
        before = len(study.get_trials(deepcopy=False, states=(TrialState.FAIL,)))
        study.optimize(run, n_trials=1, catch=(TrialFailed,))
        after = len(study.get_trials(deepcopy=False, states=(TrialState.FAIL,)))
        failures = failures + 1 if after > before else 0
        if failures >= MAX_CONSECUTIVE_FAILURES:
            print(f"tune: worker {index}: {failures} trials failed in a row, stopping "
                  f"(last: {study.trials[-1].user_attrs.get('failure', '?')})", file=sys.stderr)
            return 3
    return 0


def _worker_main(setup, index, target):
    sys.exit(worker(setup, index, target))


def _progress_line(trials, target, started, done_before):
    states = {s: 0 for s in (TrialState.COMPLETE, TrialState.PRUNED, TrialState.FAIL, TrialState.RUNNING)}
    for t in trials:
        if t.state in states and not t.user_attrs.get("interrupted"):
            states[t.state] += 1
    finished = states[TrialState.COMPLETE] + states[TrialState.PRUNED] + states[TrialState.FAIL]
    complete = [t for t in trials if t.state == TrialState.COMPLETE]
    best = max(complete, key=lambda t: t.value) if complete else None
    elapsed = time.time() - started
    new = finished - done_before
    eta = elapsed / new * max(0, target - finished) if new > 0 else float("nan")
    width = 30
    filled = min(width, int(width * finished / target)) if target else width
    bar = "#" * filled + "." * (width - filled)
    best_s = f"best {best.value:.4f} (#{best.number})" if best else "best -"
    eta_s = "?" if eta != eta else f"{int(eta) // 60}:{int(eta) % 60:02d}"
    return (f"[{bar}] {finished}/{target} trials: {states[TrialState.COMPLETE]} complete, "
            f"{states[TrialState.PRUNED]} pruned, {states[TrialState.FAIL]} failed, {states[TrialState.RUNNING]} "
            f"running; {best_s}; {int(elapsed) // 60}:{int(elapsed) % 60:02d} elapsed, ETA {eta_s}")


def tune(setup, log=print):
    """Runs the study to --trials counted trials with --jobs worker processes; returns the exit code."""
    a = setup.args
    study, storage = create_or_load(setup, log)  # the storage is reached before any drive is simulated
    setup.prepare(setup.training, log)
    stale = fail_interrupted(study, storage)
    if stale:
        log(f"{stale} trial(s) interrupted earlier are recorded as failed")
    trials = study.get_trials(deepcopy=False)
    done_before = _counted(trials)
    log(f"study '{a.study}' in {redact(setup.storage_url)}: {done_before} trial(s) already, target {a.trials}")
    if done_before >= a.trials:
        log(_progress_line(trials, a.trials, time.time(), done_before))
        return 0
    jobs = a.jobs or os.cpu_count() or 1
    ctx = multiprocessing.get_context("spawn")  # no storage connection shared with the children
    procs = [ctx.Process(target=_worker_main, args=(setup, i, a.trials)) for i in range(jobs)]
    started = time.time()
    for p in procs:
        p.start()
    last = ""
    try:
        while any(p.is_alive() for p in procs):
            time.sleep(POLL_SECONDS)
            line = _progress_line(study.get_trials(deepcopy=False), a.trials, started, done_before)
            if line.split("; ")[:2] != last.split("; ")[:2]:
                log(line)
                last = line
    except KeyboardInterrupt:
        for p in procs:
            p.terminate()
        for p in procs:
            p.join()
        fail_interrupted(study, storage)
        log("interrupted: finished trials are kept; run the same command again to resume")
        return 130
    for p in procs:
        p.join()
    trials = study.get_trials(deepcopy=False)
    log(_progress_line(trials, a.trials, started, done_before))
    log(f"{_counted(trials) - done_before} trial(s) in {time.time() - started:.0f} s with {jobs} worker(s)")
    return max(p.exitcode or 0 for p in procs)


# ---- the report ------------------------------------------------------------------------------------------

VARIANTS = (("paper", "paper's method and parameters (`config/paper/`)"),
            ("default", "default profile (`config/`)"),
            ("learned", "learned profile (`config/learned/`)"),
            ("learned_yager", "learned, Yager's rule instead of ⊛"),
            ("learned_dempster", "learned, Dempster's rule instead of ⊛"))


def best_trial(study):
    complete = study.get_trials(deepcopy=False, states=(TrialState.COMPLETE,))
    if not complete:
        raise TuneError(f"study '{study.study_name}' has no complete trial to report")
    return max(complete, key=lambda t: t.value)


PROFILE_HEADER_END = "every other key as in config/"


def refresh_profile(setup, log=print):
    """Re-renders the learned profile at --profile-out over --config: its learned values (the search space's keys,
    read from its own files) substituted into the current configuration, its header kept. A profile written before
    config/ gained or changed keys is then again every key of config/ but the learned ones."""
    d = os.path.abspath(setup.args.profile_out)
    try:
        learned = sp.base_values(d)
        with open(os.path.join(d, "fusion.yaml")) as f:
            lines = f.readlines()
    except (OSError, yaml.YAMLError) as e:
        raise TuneError(f"profile {d}: {e}")
    end = next((i for i, ln in enumerate(lines) if not ln.startswith("#") or PROFILE_HEADER_END in ln), None)
    if end is None or PROFILE_HEADER_END not in lines[end]:
        raise TuneError(f"profile {d}: fusion.yaml does not start with the header learning/tune --report writes")
    header = "".join(lines[:end + 1])
    values = {}
    for p in setup.params:
        if p.name not in learned.get(p.file, {}):
            raise TuneError(f"profile {d}: {p.file} has no {p.name}")
        values.setdefault(p.file, {})[p.name] = learned[p.file][p.name]
    sp.write_config_dir(d, values, setup.config, header)
    error = sp.check_config_dir(setup.evaluate, d)
    if error:
        raise TuneError(f"profile {d}: {error}")
    log(f"refreshed {d}/ over {setup.config}: {len(setup.params)} learned values kept")
    return 0


def report(setup, log=print):
    a = setup.args
    storage = open_storage(setup.storage_url)
    try:
        study = optuna.load_study(study_name=a.study, storage=storage)
    except KeyError:
        raise TuneError(f"storage {redact(setup.storage_url)} has no study '{a.study}'")
    best = best_trial(study)
    values = sp.split_values(best.params)
    learned_dir = os.path.abspath(a.profile_out)
    header = (f"# Learned by learning/tune (study '{a.study}', trial #{best.number}, score {best.value:.4f} on the "
              f"training drives\n# {', '.join(study.user_attrs.get('training_drives', []))}); "
              "every other key as in config/. doc/learning.md.\n")
    sp.write_config_dir(learned_dir, values, setup.config, header)
    log(f"wrote {learned_dir}/ (fusion, scan_grid, prior_grid, ibeo/scan_grid, ibeo/fusion) from trial #{best.number}")
    dirs = {"paper": (os.path.join(setup.config, "paper"), "paper"), "default": (setup.config, "default"),
            "learned": (learned_dir, "default")}
    for rule in ("yager", "dempster"):
        d = os.path.join(setup.work, "report", f"learned_{rule}")
        v = {k: dict(x) for k, x in values.items()}
        v.setdefault("fusion.yaml", {})["combination_rule"] = rule
        sp.write_config_dir(d, v, setup.config)
        dirs[f"learned_{rule}"] = (d, "default")
    held_out = setup.held_out()
    setup.prepare(setup.training + held_out, log)
    splits = (("training", setup.training), ("held_out", held_out))
    jobs = a.jobs or os.cpu_count() or 1
    results = {}
    with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
        futures = {}
        for split, ds in splits:
            for name, _ in VARIANTS:
                for d in ds:
                    cfg, variant = dirs[name]
                    futures[(split, name, d.name)] = pool.submit(d.evaluate, setup.evaluate, cfg, variant,
                                                                 a.trial_timeout)
        kitti = None
        try:
            kitti = runner.kitti_bag(os.path.join(setup.work, "kitti"), runner.tool("kitti_to_bag"))
        except runner.EvaluationError as e:
            log(f"KITTI: {e}")
        kitti_results = {}
        if kitti:
            for name in ("paper", "default", "learned"):
                cfg, variant = dirs[name]
                kitti_results[name] = pool.submit(runner.evaluate_kitti, setup.evaluate, kitti, cfg, variant,
                                                  a.trial_timeout)
        for key, f in futures.items():
            try:
                results[key] = f.result()
            except runner.EvaluationError as e:
                raise TuneError(str(e))
        kitti_results = {k: f.result() for k, f in kitti_results.items()}
    pooled = {}
    for split, ds in splits:
        for name, _ in VARIANTS:
            pooled[(split, name)] = obj.pool([results[(split, name, d.name)] for d in ds]) if ds else None
    text = _report_markdown(a, study, best, splits, pooled, kitti_results)
    os.makedirs(os.path.dirname(os.path.abspath(a.table)), exist_ok=True)
    with open(a.table, "w") as f:
        f.write(text)
    log(text)
    log(f"wrote {a.table}")
    return 0


def _report_markdown(a, study, best, splits, pooled, kitti):
    out = [f"# Learned parameters: study '{a.study}'\n",
           f"Best trial #{best.number} of {len(study.trials)} (score {best.value:.4f} on the training drives). "
           "Score: learning/maf_learning/objective.py. Drives: "
           + "; ".join(f"{split}: " + ", ".join(f"`{d.name}` ({d.preset})" for d in ds) for split, ds in splits)
           + ".\n",
           "\n## Learned values\n", "| parameter | config/ | learned |", "| --- | ---: | ---: |"]
    base = sp.base_values(os.path.abspath(a.config))
    for key, value in sorted(best.params.items()):
        file, name = key.split(".", 1)
        b = base[file + ".yaml"].get(name)
        out.append(f"| `{file}.yaml: {name}` | {b} | {sp.format_value(value)} |")
    out.append("\n## Scores (pooled over the drives of each split; ⊛ is the paper's modified Yager rule)\n")
    out.append("| drives | variant | IoU F | IoU C | IoU N | IoU S | IoU V | V precision | V recall | moving detected "
               "≤ 1 s | stopped called moving | V trail | score |")
    out.append("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    for split, _ in splits:
        ref = pooled.get((split, "paper"))
        for name, desc in VARIANTS:
            p = pooled.get((split, name))
            if not p:
                continue
            out.append(f"| {split.replace('_', '-')} | {desc} | " + " | ".join(f"{p[f'iou_{c}']:.3f}" for c in "FCNSV")
                       + f" | {p['v_precision']:.3f} | {p['v_recall']:.3f} | {p['moving_detected']}/"
                       f"{p['moving_visible']} | {p['stopped_moving']:.3f} | {p['trail']:.1f} | "
                       f"{obj.score(p, ref):.4f} |")
    out.append("\n## Moving objects (pooled per split; doc/evaluation.md, \"Scoring moving objects\")\n")
    out.append("| drives | variant | movers seen | detected ≤ 0.5 s | detected ≤ 1 s | never V | median delay (s) | "
               "mean V share | S share (cells) |")
    out.append("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    for split, _ in splits:
        for name, desc in VARIANTS:
            p = pooled.get((split, name))
            if not p:
                continue
            mv = p["movers"]
            median = "never" if mv["median_delay_s"] is None else f"{mv['median_delay_s']:.1f}"
            out.append(f"| {split.replace('_', '-')} | {desc} | {mv['seen']} | {mv['within_0_5s']}/{mv['seen']} | "
                       f"{mv['within_1s']}/{mv['seen']} | {mv['never']} | {median} | {mv['mean_v_share']:.2f} | "
                       f"{mv['s_share']:.2f} |")
    if kitti:
        out.append("\n## Real KITTI 00 frames 0–9 (never used for learning; no map)\n")
        out.append("| variant | V cells / sweep | false V / labelled sweep | V on static points / labelled sweep | "
                   "motorcyclist cells decided V |")
        out.append("| --- | ---: | ---: | ---: | ---: |")
        for name, desc in VARIANTS:
            if name in kitti:
                k = kitti[name]
                out.append(f"| {desc} | {k['v_cells_per_sweep']:.1f} | {k['false_v_per_labelled_sweep']:.1f} | "
                           f"{k['v_on_static_per_labelled_sweep']:.1f} | {k['mover_cells_v_share']:.2f} |")
    held = pooled.get(("held_out", "learned"))
    paper = pooled.get(("held_out", "paper"))
    default = pooled.get(("held_out", "default"))
    if held and paper and default:
        losses = {c: (paper[f"iou_{c}"] - held[f"iou_{c}"]) / paper[f"iou_{c}"] if paper[f"iou_{c}"] else 0.0
                  for c in "FCNSV"}
        worst = max(losses, key=losses.get)
        vp = held["v_precision"] > paper["v_precision"]
        det = held["detected"] > paper["detected"]
        iou_ok = losses[worst] <= 0.02
        beats_default = obj.score(held, paper) > obj.score(default, paper)
        out.append("\n## Held-out verdict\n")
        out.append(f"- learned vs paper, V precision: {held['v_precision']:.3f} vs {paper['v_precision']:.3f} — "
                   f"{'wins' if vp else 'does not win'}")
        out.append(f"- learned vs paper, moving objects detected: {held['moving_detected']}/{held['moving_visible']} "
                   f"vs {paper['moving_detected']}/{paper['moving_visible']} — {'wins' if det else 'does not win'}")
        if losses[worst] > 0:
            out.append(f"- largest class IoU loss against paper: {worst} {100 * losses[worst]:.1f} % (relative) — "
                       f"{'within' if iou_ok else 'over'} 2 %")
        else:
            out.append(f"- no class IoU below the paper's (smallest gain: {worst} +{-100 * losses[worst]:.1f} %, "
                       "relative) — within 2 %")
        out.append(f"- learned vs default, score on held-out drives: {obj.score(held, paper):.4f} vs "
                   f"{obj.score(default, paper):.4f} — {'learned wins' if beats_default else 'default wins'}")
        real_ok = True
        if "learned" in kitti and "default" in kitti:
            k_l, k_d = kitti["learned"], kitti["default"]
            real_ok = (k_l["mover_cells_v_share"] >= k_d["mover_cells_v_share"] and
                       k_l["false_v_per_labelled_sweep"] <= k_d["false_v_per_labelled_sweep"] + 1.0)
            out.append(f"- real KITTI frames, learned vs default: false V {k_l['false_v_per_labelled_sweep']:.1f} vs "
                       f"{k_d['false_v_per_labelled_sweep']:.1f} per labelled sweep, the moving motorcyclist's cells "
                       f"decided V {k_l['mover_cells_v_share']:.2f} vs {k_d['mover_cells_v_share']:.2f} — "
                       f"{'no worse' if real_ok else 'worse on the real mover'}")
        promote = vp and det and iou_ok and beats_default and real_ok
        out.append(f"- **{'the learned profile may become the default' if promote else 'the default stays'}** "
                   "(it must win on the held-out drives and be no worse on the real frames)")
    return "\n".join(out) + "\n"
