"""The family "cli files": the ``tubefsi`` command run in-process (:func:`tubefsi.cli.main`) on
malformed network files and bad output options, and with a closed, broken or ASCII-only
standard output.

The contract (``docs/cli.md``): a bad file or argument ends with exit status 2 and one line
``tubefsi: error: ...`` on stderr, never ``internal error`` nor a traceback; a closed or broken
standard output ends the command quietly; an ASCII-only one still gets every command's output.
"""

from __future__ import annotations

import contextlib
import copy
import io
import json
import math
import os
import tempfile

from ... import cli
from ._core import Probe

#: A valid network file (rigid tubes and a Newtonian fluid: solved in milliseconds).
_NETWORK = {
    "rheology": "newtonian:viscosity=1e-3",
    "tubes": [{"u": "a", "v": "b", "name": "ab", "wall": "rigid",
               "tube": {"radius": 1e-4, "thickness": 3e-5, "length": 1e-2}},
              {"u": "b", "v": "c", "wall": "rigid", "tube": "radius=1e-4,thickness=3e-5,length=1e-2",
               "external_pressure": 0.0, "rheology": "newtonian:viscosity=2e-3"}],
    "pressures": {"a": 300, "c": 0},
    "inflows": {},
    "positions": {"a": [0, 0], "b": [1, 0], "c": [2, 0]},
}

#: Each field of the file, as a path into it, with the JSON types it accepts ("number": an int or
#: a float, not a boolean); a value of another type must be refused.
_FIELDS = {
    ("rheology",): {"string"},
    ("tubes",): {"array"},
    ("tubes", 0): {"object"},
    ("tubes", 0, "u"): {"string"},
    ("tubes", 0, "v"): {"string"},
    ("tubes", 0, "name"): {"string", "number", "null"},
    ("tubes", 0, "wall"): {"string"},
    ("tubes", 0, "tube"): {"object", "string"},
    ("tubes", 0, "tube", "radius"): {"number", "string"},
    ("tubes", 0, "tube", "length"): {"number", "string"},
    ("tubes", 1, "rheology"): {"string"},
    ("tubes", 1, "external_pressure"): {"number"},
    ("pressures",): {"object"},
    ("pressures", "a"): {"number"},
    ("inflows",): {"object"},
    ("positions",): {"object"},
    ("positions", "a"): {"array"},
    ("positions", "a", 0): {"number"},
}


def _nested(depth):
    value = 1.0
    for _ in range(depth):
        value = [value]
    return value


#: Values of every JSON type, some of them extreme, put in each field in turn.
_VALUES = (5, -1, 1.5, 0, 10**400, math.nan, math.inf, True, None, "x", "", [], [1, 2], ["a", "b"], {}, {"x": 1},
           _nested(50))


#: Valid sizes (m) left out of the tube's fields: a 5 m tube next to one of 0.1 mm is the network
#: solver's problem (a conductance ratio beyond 1/eps), not the file's; the families "fields" and
#: "entry points" probe the library's ranges.
_GEOMETRY = (5, 1.5)


def _kind(value):
    if isinstance(value, bool):
        return "bool"
    if isinstance(value, (int, float)):
        return "number"
    return {str: "string", list: "array", dict: "object", type(None): "null"}[type(value)]


def _with(path, value):
    """The valid network with the field at ``path`` set to ``value`` (``...``: removed)."""
    spec = copy.deepcopy(_NETWORK)
    holder = spec
    for key in path[:-1]:
        holder = holder[key]
    if value is ...:
        del holder[path[-1]]
    else:
        holder[path[-1]] = value
    return spec


class _Broken(io.StringIO):
    """A standard output whose reader went away (``tubefsi ... | head``)."""

    def write(self, text):
        raise BrokenPipeError(32, "Broken pipe")


def _closed():
    stream = io.StringIO()
    stream.close()
    return stream


def _run(argv, files=None, stdout=io.StringIO):
    """``(status, stdout, stderr)`` of ``tubefsi ARGV`` in-process, with ``files`` (name -> bytes)
    written to a temporary directory whose path replaces ``{dir}`` in the arguments; ``stdout``
    makes the standard output stream (None: closed)."""
    with tempfile.TemporaryDirectory() as tmp:
        for name, content in (files or {}).items():
            with open(os.path.join(tmp, name), "wb") as fh:
                fh.write(content)
        out, err = (stdout() if stdout is not None else None), io.StringIO()
        here = os.getcwd()
        os.chdir(tmp)                      # whatever a command writes by mistake lands here
        try:
            with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
                status = cli.main([arg.replace("{dir}", tmp) for arg in argv])
        except SystemExit as exc:          # the contract's breach, not the campaign's end
            status = f"SystemExit({exc.code!r})"
        finally:
            os.chdir(here)
        if isinstance(out, io.TextIOWrapper):      # the ASCII-only stream
            out.flush()
            written = out.buffer.getvalue().decode("ascii")
        elif isinstance(out, io.StringIO) and not out.closed:
            written = out.getvalue()
        else:
            written = ""
        return status, written, err.getvalue()


def _fails(*words):
    """The check of a refused input: status 2, nothing on stdout, one error line naming ``words``."""
    def check(result):
        status, out, err = result
        lines = err.splitlines()
        if status != 2 or len(lines) != 1 or not lines[0].startswith("tubefsi: error: ") or out:
            return f"status {status!r}, stdout {out[:80]!r}, stderr {err[:300]!r}"
        if "internal error" in err or "Traceback" in err:
            return err[:300]
        missing = [w for w in words if w not in lines[0]]
        return f"does not name {missing}: {lines[0][:300]}" if missing else None
    return check


def _succeeds_or_fails(result):
    """Either answer, cleanly: status 0 without an error, or the one-line refusal."""
    status, out, err = result
    if status == 0:
        return None if "error" not in err and "Traceback" not in err else err[:300]
    return _fails()(result)


def _quiet(result):
    """A closed or broken standard output: status 0 and nothing on stderr."""
    status, _, err = result
    return None if status == 0 and not err else f"status {status!r}, stderr {err[:300]!r}"


def _ascii(result):
    status, out, err = result
    if status != 0 or "Traceback" in err or "error" in err:
        return f"status {status!r}, stderr {err[:300]!r}"
    return None if out and out.isascii() else f"stdout {out[:80]!r}"


def _network_probe(label, content, check):
    files = {"net.json": content if isinstance(content, bytes) else json.dumps(content).encode()}
    return Probe("cli network", label, lambda: _run(["network", "{dir}/net.json"], files), check=check)


def _network_file_probes():
    yield _network_probe("the valid file", _NETWORK, lambda r: None if r[0] == 0 and json.loads(r[1])["nodes"]
                         else f"status {r[0]!r}, stderr {r[2][:300]!r}")
    raw = {"empty": b"", "whitespace": b" \n", "unfinished": b"{", "not JSON": b"{tubes: 1}",
           "binary": bytes(range(256)), "UTF-16": json.dumps(_NETWORK).encode("utf-16"),
           "an integer of 10^5 digits": b'{"tubes": [' + b"9" * 100_000 + b"]}",
           "arrays 10^5 deep": b"[" * 100_000 + b"]" * 100_000,
           "objects 10^5 deep": b'{"a":' * 100_000 + b"1" + b"}" * 100_000,
           "a tube 10^5 deep": b'{"tubes": [' + b"[" * 100_000 + b"]" * 100_000 + b"]}"}
    for label, content in raw.items():
        yield _network_probe(label, content, _fails("net.json"))
    for value in (None, 5, "x", [], {}, {"tubes": 5}, {"tubes": []}, {"tubes": {}}, {**_NETWORK, "pipes": 1},
                  {**_NETWORK, "tubes": [{**_NETWORK["tubes"][0], "colour": "red"}]}):
        yield _network_probe(f"file {json.dumps(value)[:60]}", value, _fails("net.json"))
    for path, kinds in _FIELDS.items():
        where = f"{path[0]}[{path[1]}]" if len(path) > 1 and isinstance(path[1], int) else path[0]
        for value in _VALUES:
            if len(path) > 1 and path[-2] == "tube" and value in _GEOMETRY:
                continue
            label = f"{'.'.join(map(str, path))} = {json.dumps(value)[:40]}"
            content = json.dumps(_with(path, value)).encode()
            check = _succeeds_or_fails if _kind(value) in kinds else _fails("net.json", where)
            yield _network_probe(label, content, check)
        yield _network_probe(f"{'.'.join(map(str, path))} left out", _with(path, ...), _succeeds_or_fails)
    for key in ("u", "v", "wall", "tube"):                   # each required key of a tube
        yield _network_probe(f"tubes[0].{key} left out", _with(("tubes", 0, key), ...), _fails("net.json", "tubes[0]"))


_SCENE = ("--rheology", "newtonian:viscosity=1e-3", "--wall", "rigid", "--tube", "radius=1e-4,thickness=3e-5,length=1e-2")


def _output_probes():
    curve = ["curve", *_SCENE, "--flow-rate", "0:1e-9:3"]
    network = ["network", "{dir}/net.json"]
    files = {"net.json": json.dumps(_NETWORK).encode()}
    refused = {
        "curve --output y.png": [*curve, "--output", "{dir}/y.png"],
        "curve --output y.xlsx": [*curve, "--output", "{dir}/y.xlsx"],
        "curve --output y.txt": [*curve, "--output", "{dir}/y.txt"],
        "curve --output ''": [*curve, "--output", ""],
        "curve --plot ''": [*curve, "--plot", ""],
        "curve --plot y.xlsx": [*curve, "--plot", "{dir}/y.xlsx"],
        "curve --output a directory": [*curve, "--output", "{dir}"],
        "curve --output in a missing directory": [*curve, "--output", "{dir}/no/such/y.csv"],
        "curve --format netcdf to stdout": [*curve, "--format", "netcdf"],
        "network --output y.png": [*network, "--output", "{dir}/y.png"],
        "network --output ''": [*network, "--output", ""],
        "network --plot ''": [*network, "--plot", ""],
        "network --format csv to stdout": [*network, "--format", "csv"],
        "network of a missing file": ["network", "{dir}/missing.json"],
        "network of a directory": ["network", "{dir}"],
        "reproduce ''": ["reproduce", ""],
    }
    for label, argv in refused.items():
        yield Probe("cli output", label, lambda a=argv: _run(a, files), check=_fails())
    accepted = {
        "curve --format csv --output y.txt": [*curve, "--format", "csv", "--output", "{dir}/y.txt"],
        "curve --output y (no suffix)": [*curve, "--output", "{dir}/y"],
        "network --output y.json": [*network, "--output", "{dir}/y.json"],
    }
    for label, argv in accepted.items():
        yield Probe("cli output", label, lambda a=argv: _run(a, files),
                    check=lambda r: None if r[0] == 0 else f"status {r[0]!r}, stderr {r[2][:300]!r}")
    commands = {"solve --json": ["solve", *_SCENE, "--flow-rate", "1e-9", "--json"],
                "solve": ["solve", *_SCENE, "--flow-rate", "1e-9"], "curve": curve, "network": network,
                "list": ["list"], "--help": ["--help"]}
    for label, argv in commands.items():
        for how, stdout in (("closed (None)", None), ("closed stream", _closed), ("broken pipe", _Broken)):
            yield Probe("cli stdout", f"{label}, stdout {how}", lambda a=argv, s=stdout: _run(a, files, s),
                        check=_quiet)
        yield Probe("cli stdout", f"{label}, ASCII-only stdout",
                    lambda a=argv: _run(a, files, lambda: io.TextIOWrapper(io.BytesIO(), encoding="ascii")),
                    check=_ascii)


def _cli_family(chosen):
    """The probes of the family "cli files" (model-free: with ``chosen.core`` only)."""
    if chosen.core:
        yield from _network_file_probes()
        yield from _output_probes()
