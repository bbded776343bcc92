"""evio from Python: a sequence's streams as NumPy arrays, and the commands
simulate, estimate and evaluate with exactly the options of the command line.

Reading (compiled, the project's own readers; see python/sequence_arrays.h):
    read_events(folder, t_start_ns=None, t_end_ns=None)   structured array t:i8 x:u2 y:u2 p:u1
    read_event_columns(folder, ...)                        dict of column arrays, no copy
    iter_events(folder, chunk_size=2**20, ...)             chunks: memory stays flat
    iter_frames(folder)                                    (t_ns, uint8 array H x W), one at a time
    read_imu(folder)                                       t:i8 gyro:f8[3] acc:f8[3]
    read_groundtruth(folder)                               t:i8 p:f8[3] q:f8[4] (x y z w)

Commands (run the `evio` binary, so options are parsed and checked by the
same code as on the command line; a dict of options becomes `--set key=value`
overrides, nested dicts dotted keys; an unknown key is the CLI's error):
    simulate(scenario, output, options=None, threads=None)  -> simulation_stats.yaml as a dict
    estimate(sequence, output, method=None, config=None, options=None, init=None)
                                                            -> status.yaml as a dict (+ exit_code)
    evaluate(estimate, groundtruth, paper=False, config=None, options=None)
                                                            -> the metrics JSON as a dict
    run(args)                                               -> any evio command line; its exit code

Every failure raises evio.Error with the message the CLI prints.
"""
import json
import os
import shutil
import subprocess
import tempfile

import yaml

from ._native import Error, iter_events, iter_frames, read_event_columns, read_events, read_groundtruth, read_imu
from ._native import set_media_module as _set_media_module
from ._paths import BIN_FROM_PACKAGE, MEDIA_FROM_PACKAGE, VERSION

# Frames in formats other than PNG are decoded by the media module beside the package.
_set_media_module(os.path.normpath(os.path.join(os.path.dirname(__file__), MEDIA_FROM_PACKAGE)))

__version__ = VERSION
__all__ = ["Error", "read_events", "read_event_columns", "iter_events", "iter_frames", "read_imu",
           "read_groundtruth", "simulate", "estimate", "evaluate", "run", "binary"]


def binary():
    """The evio binary the commands run: $EVIO_BIN, else the one installed or
    built beside this package, else `evio` on PATH."""
    if os.environ.get("EVIO_BIN"):
        return os.environ["EVIO_BIN"]
    beside = os.path.normpath(os.path.join(os.path.dirname(__file__), BIN_FROM_PACKAGE))
    if os.access(beside, os.X_OK):
        return beside
    found = shutil.which("evio")
    if found:
        return found
    raise Error("the evio binary was not found beside the package (%s), in $EVIO_BIN or on PATH" % beside)


def _text(value, key):
    """One option value as the command line writes it."""
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return repr(value)  # a float's repr round-trips
    if isinstance(value, str):
        return value
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_text(v, key) for v in value) + "]"
    raise Error("%s: cannot pass a value of Python type %s as an option" % (key, type(value).__name__))


def _overrides(options, prefix=""):
    """{'rig': {'imu': {'update_rate_hz': 200}}} -> ['rig.imu.update_rate_hz=200']."""
    if options is None:
        return []
    if not isinstance(options, dict):
        raise Error("options: expected a dict (or None), got %s" % type(options).__name__)
    out = []
    for key, value in options.items():
        if not isinstance(key, str):
            raise Error("%s<key>: option keys must be strings" % prefix)
        if isinstance(value, dict):
            out += _overrides(value, prefix + key + ".")
        else:
            out.append(prefix + key + "=" + _text(value, prefix + key))
    return out


def _set_args(options):
    args = []
    for o in _overrides(options):
        args += ["--set", o]
    return args


def run(args):
    """Runs `evio <args>`; returns its exit code (0, or 3 when it ran but its
    result failed); raises evio.Error with the CLI's message otherwise."""
    done = subprocess.run([binary()] + [str(a) for a in args], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                          text=True)
    if done.returncode not in (0, 3):
        lines = [l for l in done.stderr.splitlines() if l.strip()]
        message = lines[-1] if lines else "exit code %d" % done.returncode
        raise Error(message[len("evio: error: "):] if message.startswith("evio: error: ") else message)
    return done.returncode


def _read_yaml(path):
    with open(path) as f:
        return yaml.safe_load(f)


def simulate(scenario, output, options=None, threads=None):
    """`evio simulate scenario -o output --set …`; returns simulation_stats.yaml as a dict."""
    args = ["simulate", scenario, "-o", output, "-q"] + _set_args(options)
    if threads is not None:
        args += ["--threads", str(int(threads))]
    run(args)
    return _read_yaml(os.path.join(output, "simulation_stats.yaml"))


def estimate(sequence, output, method=None, config=None, options=None, init=None):
    """`evio estimate`; config is a YAML path or a dict (the same as --set on
    the defaults); returns status.yaml as a dict with the exit code."""
    args = ["estimate", sequence, "-o", output, "-q"]
    if method is not None:
        args += ["--method", method]
    if isinstance(config, (str, os.PathLike)):
        args += ["--config", os.fspath(config)]
    else:
        args += _set_args(config)
    args += _set_args(options)
    if init is not None:
        args += ["--init", init]
    code = run(args)
    status = _read_yaml(os.path.join(output, "status.yaml"))
    status["exit_code"] = code
    return status


def evaluate(estimate, groundtruth, paper=False, config=None, options=None):
    """`evio evaluate`; returns the metrics (the JSON of `-o metrics.json`) as a dict."""
    with tempfile.TemporaryDirectory(prefix="evio-python.") as scratch:
        out = os.path.join(scratch, "metrics.json")
        args = ["evaluate", estimate, groundtruth, "-o", out, "-q"] + (["--paper"] if paper else [])
        if isinstance(config, (str, os.PathLike)):
            args += ["--config", os.fspath(config)]
        else:
            args += _set_args(config)
        args += _set_args(options)
        run(args)
        with open(out) as f:
            return json.load(f)
