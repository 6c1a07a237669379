"""The coupling protocol (proto/PROTOCOL.md, version 2) in pure Python.

Written from PROTOCOL.md alone, to show that a solver needs nothing but numpy
and pyzmq to talk to the coupler. Codec: encode(Message) -> list of frames
(bytes), decode(frames) -> Message, with the same checks as the C codec; a
violation raises ProtocolError. Link: connect(), send(), recv(timeout_ms).

A minimal solid solver loop::

    sock = mpsproto.connect(zmq.Context(), endpoint)
    mpsproto.send(sock, Message(Type.HELLO, text=f"role=solid model=py pid={os.getpid()}"))
    cfg = mpsproto.recv(sock, 60000)            # CONFIG (or REJECT)
    ...
    while True:
        m = mpsproto.recv(sock, timeout_ms)
        if m.type == Type.STOP: ...send BYE...; break
        # ADVANCE: m.n_sub sub-steps of m.dt / m.n_sub with loads m.id, m.force
        mpsproto.send(sock, Message(Type.RESULT, payload=Payload.STATE, step=m.step,
                                    time=m.time + m.dt, dt=my_dt, id=..., x=..., v=...,
                                    surface=..., fixed=...))
"""

from __future__ import annotations

import enum
import math
import struct
from dataclasses import dataclass, field
from typing import Optional, Sequence

import numpy as np

VERSION = 2
DIM = 2
HEADER = struct.Struct("<4sHHIHHqiiddQII16x")  # 80 bytes, PROTOCOL.md section 3
MAGIC = b"MPSC"
MAX_COUNT = 2147483647
MAX_PROBES = 65536
MAX_TEXT = 1 << 20
LINGER_MS = 1000
SEND_TIMEOUT_MS = 10000

F_TEXT = 1
F_SNAPSHOT = 2
F_PROBES = 4
F_CHECKPOINT = 8  # ADVANCE: write a checkpoint after the step (caps=checkpoint)

STATUS_NAMES = ("input", "io", "memory", "library", "solver", "diverged", "protocol",
                "timeout", "peer", "interrupted")

# CONFIG keys (PROTOCOL.md 4). A solver answers a key it does not know with
# ERROR "input: ...". "motion" (value: the case's motion.kind) is sent only
# when the case's tank moves: a solver that cannot apply the moving frame's
# body forces (the case's motion block, docs/sloshing.md) refuses it.
CONFIG_KEYS = ("case", "out", "prefix", "timeout_ms", "rollback", "motion", "restart")


class Type(enum.IntEnum):
    HELLO = 1
    REJECT = 2
    CONFIG = 3
    READY = 4
    ADVANCE = 5
    RESULT = 6
    STOP = 7
    BYE = 8
    ERROR = 9
    ABORT = 10


class Payload(enum.IntEnum):
    NONE = 0
    STATE = 1
    LOADS = 2


# Array frames per payload: (name, little-endian dtype, vector?)
ARRAYS = {
    Payload.NONE: (),
    Payload.STATE: (("id", "<i4", False), ("x", "<f8", True), ("v", "<f8", True),
                    ("surface", "u1", False), ("fixed", "u1", False)),
    Payload.LOADS: (("id", "<i4", False), ("pressure", "<f8", False), ("force", "<f8", True)),
}


class ProtocolError(Exception):
    """A message breaks PROTOCOL.md (the C side's MPS_EPROTO)."""


@dataclass
class Message:
    type: int
    payload: int = Payload.NONE
    flags: int = 0          # F_SNAPSHOT, F_PROBES; F_TEXT is derived from text
    step: int = 0
    iteration: int = 0
    n_sub: int = 0
    time: float = 0.0       # s
    dt: float = 0.0         # s
    id: Optional[np.ndarray] = None        # int32 [count]
    x: Optional[np.ndarray] = None         # float64 [count, DIM], m
    v: Optional[np.ndarray] = None         # float64 [count, DIM], m/s
    surface: Optional[np.ndarray] = None   # uint8 [count]
    fixed: Optional[np.ndarray] = None     # uint8 [count]
    pressure: Optional[np.ndarray] = None  # float64 [count], Pa
    force: Optional[np.ndarray] = None     # float64 [count, DIM], N (per m depth)
    probes: Optional[np.ndarray] = None    # float64 [nprobes] (RESULT with F_PROBES)
    text: Optional[str] = None
    nprobes: int = field(default=0)        # READY: derived from text; RESULT: from probes

    @property
    def count(self) -> int:
        return 0 if self.payload == Payload.NONE or self.id is None else len(self.id)

    def probe_names(self) -> list:
        return self.text.split(",") if self.text else []


def _fail(msg: "Message | None", what: str) -> None:
    name = Type(msg.type).name if msg is not None and msg.type in Type._value2member_map_ else None
    raise ProtocolError(f"{name}: {what}" if name else what)


def _has_probe_frame(m: Message) -> bool:
    return m.type == Type.RESULT and bool(m.flags & F_PROBES)


def _kv(text: str, sep: str) -> dict:
    out = {}
    for item in text.split(sep):
        if "=" in item:
            k, v = item.split("=", 1)
            out.setdefault(k, v)
    return out


def _check(m: Message, dim: int = DIM) -> None:
    """Every rule of PROTOCOL.md beyond the wire layout (shared by encode and decode)."""
    t = m.type
    if t not in Type._value2member_map_:
        raise ProtocolError(f"unknown message type {t} (known: 1..10)")
    if m.payload not in Payload._value2member_map_:
        _fail(m, f"unknown payload kind {m.payload} (known: 0..2)")
    ok = {Type.READY: m.payload != Payload.LOADS, Type.ADVANCE: True,
          Type.RESULT: m.payload != Payload.NONE}.get(Type(t), m.payload == Payload.NONE)
    if not ok:
        _fail(m, f"payload {Payload(m.payload).name} not allowed")
    known = F_TEXT | F_SNAPSHOT | F_PROBES | F_CHECKPOINT
    if m.flags & ~known:
        _fail(m, f"flags {m.flags:#x} have unknown bits {m.flags & ~known:#x}")
    if m.flags & F_SNAPSHOT and t != Type.ADVANCE:
        _fail(m, "flag SNAPSHOT is for ADVANCE only")
    if m.flags & F_CHECKPOINT and t != Type.ADVANCE:
        _fail(m, "flag CHECKPOINT is for ADVANCE only")
    if m.flags & F_PROBES and t not in (Type.ADVANCE, Type.RESULT):
        _fail(m, "flag PROBES is for ADVANCE and RESULT only")
    if bool(m.flags & F_TEXT) != (m.text is not None):
        _fail(m, "flag TEXT does not match the presence of a text")
    rule = -1 if t == Type.READY else 0 if t in (Type.ADVANCE, Type.RESULT, Type.STOP) else 1
    if rule == 1 and m.text is None:
        _fail(m, "text frame missing (required)")
    if rule == 0 and m.text is not None:
        _fail(m, "unexpected text frame")
    if m.text is not None:
        if "\0" in m.text:
            _fail(m, f"text has a NUL byte at offset {m.text.index(chr(0))}")
        if len(m.text.encode("utf-8", "surrogatepass")) > MAX_TEXT:
            _fail(m, f"text is longer than {MAX_TEXT} bytes")
    if m.step < 0:
        _fail(m, f"step = {m.step}: must be >= 0")
    if m.iteration < 0:
        _fail(m, f"iteration = {m.iteration}: must be >= 0")
    if m.n_sub < 0 or (t == Type.ADVANCE and m.n_sub < 1) or (t != Type.ADVANCE and m.n_sub):
        _fail(m, f"n_sub = {m.n_sub}: must be " + (">= 1" if t == Type.ADVANCE else "0 (ADVANCE only)"))
    if not math.isfinite(m.time):
        _fail(m, f"time = {m.time}: must be finite")
    positive = t in (Type.ADVANCE, Type.READY, Type.RESULT)
    if not math.isfinite(m.dt) or m.dt < 0 or (positive and not m.dt > 0):
        _fail(m, f"dt = {m.dt}: must be finite and " + ("> 0" if positive else ">= 0"))
    count = m.count
    if count > MAX_COUNT:
        _fail(m, f"count = {count} exceeds {MAX_COUNT}")
    allowed = t == Type.READY or _has_probe_frame(m)
    if m.nprobes < 0 or m.nprobes > MAX_PROBES or (not allowed and m.nprobes):
        _fail(m, f"nprobes = {m.nprobes}: must be " + ("in 0..65536" if allowed else "0 here"))
    if t == Type.READY:
        names = m.probe_names()
        for n in names:
            if not n:
                _fail(m, f"probe names '{m.text}': empty name")
            if any(ord(c) <= 32 or ord(c) == 127 for c in n):
                _fail(m, f"probe names '{m.text}': whitespace or control character")
        if len(names) != m.nprobes:
            _fail(m, f"{len(names)} probe names, nprobes = {m.nprobes}")
    if _has_probe_frame(m):
        p = np.zeros(0) if m.probes is None else np.asarray(m.probes)
        if p.shape != (m.nprobes,):
            _fail(m, f"probes has shape {p.shape}, nprobes = {m.nprobes}")
    if t == Type.HELLO:
        kv = _kv(m.text, " ")
        if kv.get("role") not in ("fluid", "solid"):
            _fail(m, f"text '{m.text}': needs role=fluid or role=solid")
        if not kv.get("model"):
            _fail(m, f"text '{m.text}': needs model=NAME")
        if not kv.get("pid", "").isdigit() or not kv["pid"].isascii():
            _fail(m, f"text '{m.text}': needs pid=N (decimal)")
    if t == Type.CONFIG:
        for line in m.text.split("\n"):
            if line and (line.find("=") <= 0):
                _fail(m, f"line '{line}': expected key=value")
        kv = _kv(m.text, "\n")
        for k in ("case", "out", "prefix"):
            if k not in kv:
                _fail(m, f"key '{k}' missing (needs case, out, prefix)")
    if t == Type.ERROR and not any(m.text.startswith(s + ": ") for s in STATUS_NAMES):
        _fail(m, f"text '{m.text[:40]}' must start with 'STATUS: ' ({', '.join(STATUS_NAMES)})")
    # arrays
    if m.payload == Payload.NONE:
        return
    for name, dt, vec in ARRAYS[Payload(m.payload)]:
        a = getattr(m, name)
        if a is None:
            if count:
                _fail(m, f"array {name} is None with count = {count}")
            continue
        shape = (count, dim) if vec else (count,)
        if np.shape(a) != shape:
            _fail(m, f"array {name} has shape {np.shape(a)}, expected {shape}")
    if count == 0:
        return
    ids = np.asarray(m.id)
    if (ids < 0).any():
        i = int(np.argmax(ids < 0))
        _fail(m, f"id[{i}] = {ids[i]}: ids must be >= 0")
    if m.payload == Payload.STATE:
        bad = (np.asarray(m.surface) > 1) | (np.asarray(m.fixed) > 1)
        if bad.any():
            i = int(np.argmax(bad))
            _fail(m, f"surface[{i}] = {m.surface[i]}, fixed[{i}] = {m.fixed[i]}: must be 0 or 1")
        floats = ("x", "v")
    else:
        floats = ("pressure", "force")
    for name in floats:
        a = np.asarray(getattr(m, name), dtype=np.float64)
        if not np.isfinite(a).all():
            flat = int(np.argmax(~np.isfinite(a.reshape(-1))))
            if a.ndim == 1:
                _fail(m, f"{name}[{flat}] = {a[flat]} (id {ids[flat]}): must be finite")
            i, d = divmod(flat, dim)
            _fail(m, f"{name}[{i}][{d}] = {a[i, d]} (id {ids[i]}): must be finite")


def encode(m: Message, dim: int = DIM) -> list:
    """The frames of m (bytes): header, arrays, probe frame, text. Derives
    F_TEXT from text and nprobes from the probe names (READY) or values (RESULT)."""
    flags = (m.flags & ~F_TEXT) | (F_TEXT if m.text is not None else 0)
    nprobes = m.nprobes
    if m.type == Type.READY:
        nprobes = len(m.probe_names())
    elif m.type == Type.RESULT and m.flags & F_PROBES:
        nprobes = 0 if m.probes is None else len(m.probes)
    c = Message(**{**m.__dict__, "flags": flags, "nprobes": nprobes})
    _check(c, dim)
    arrays = [] if c.payload not in ARRAYS else ARRAYS[Payload(c.payload)]
    frames = []
    count = c.count
    for name, dt, vec in arrays:
        a = getattr(c, name)
        a = np.zeros((count, dim) if vec else count, dtype=dt) if a is None else a
        frames.append(np.ascontiguousarray(a, dtype=dt).tobytes())
    if _has_probe_frame(c):
        p = np.zeros(0) if c.probes is None else c.probes
        frames.append(np.ascontiguousarray(p, dtype="<f8").tobytes())
    header = HEADER.pack(MAGIC, VERSION, int(c.type), flags, dim, int(c.payload), c.step,
                         c.iteration, c.n_sub, float(c.time), float(c.dt), count, len(frames),
                         nprobes)
    out = [header] + frames
    if c.text is not None:
        out.append(c.text.encode("utf-8"))
    return out


def decode(frames: Sequence, dim: int = DIM) -> Message:
    """Checks and decodes the frames of one message (bytes-like each)."""
    frames = [bytes(f) for f in frames]
    if not frames:
        raise ProtocolError("empty message: at least the header frame needed")
    h = frames[0]
    if len(h) < 8:
        raise ProtocolError(f"header frame is {len(h)} bytes, expected {HEADER.size}")
    if h[:4] != MAGIC:
        raise ProtocolError(f"bad magic {h[:4]!r}, expected b'MPSC': not a coupling-protocol message")
    version, mtype = struct.unpack_from("<HH", h, 4)
    if version != VERSION:
        why = ""
        if mtype == Type.REJECT and len(frames) >= 2:
            why = f" (the peer's REJECT says: {frames[-1][:160].decode('utf-8', 'replace')})"
        raise ProtocolError(f"protocol version {version} received, this build speaks version {VERSION}{why}")
    if len(h) != HEADER.size:
        raise ProtocolError(f"header frame is {len(h)} bytes, expected {HEADER.size}")
    (_, _, mtype, flags, hdim, payload, step, iteration, n_sub, time, dt, count, narrays,
     nprobes) = HEADER.unpack(h)
    if mtype not in Type._value2member_map_:
        raise ProtocolError(f"unknown message type {mtype} (known: 1..10)")
    m = Message(Type(mtype), payload, flags, step, iteration, n_sub, time, dt, nprobes=nprobes)
    if hdim != dim:
        _fail(m, f"dim = {hdim}, this build is {dim}D")
    if payload not in Payload._value2member_map_:
        _fail(m, f"unknown payload kind {payload} (known: 0..2)")
    m.payload = Payload(payload)
    if count > MAX_COUNT:
        _fail(m, f"count = {count} exceeds {MAX_COUNT}")
    if payload == Payload.NONE and count:
        _fail(m, f"count = {count} with payload NONE")
    if nprobes > MAX_PROBES:
        _fail(m, f"nprobes = {nprobes} exceeds {MAX_PROBES}")
    arrays = ARRAYS[m.payload]
    probes = _has_probe_frame(m)
    if narrays != len(arrays) + probes:
        _fail(m, f"narrays = {narrays}, expected {len(arrays) + probes} for payload "
                 f"{m.payload.name}" + (" plus the probe frame" if probes else ""))
    text = bool(flags & F_TEXT)
    want = 1 + narrays + text
    if len(frames) != want:
        _fail(m, f"{len(frames)} frames, expected {want} (header + {narrays} arrays"
                 + (" + text)" if text else ")"))
    for k, (name, dt_, vec) in enumerate(arrays):
        f = frames[1 + k]
        comps = dim if vec else 1
        size = np.dtype(dt_).itemsize
        if len(f) != count * comps * size:
            _fail(m, f"frame {k + 1} ({name}): {len(f)} bytes, expected {count * comps * size} "
                     f"(count {count} x {comps} x {'i32' if dt_ == '<i4' else 'u8' if size == 1 else 'f64'})")
        a = np.frombuffer(f, dtype=dt_)
        setattr(m, name, a.reshape(count, dim) if vec else a)
    if probes:
        f = frames[1 + len(arrays)]
        if len(f) != nprobes * 8:
            _fail(m, f"frame {len(arrays) + 1} (probes): {len(f)} bytes, expected {nprobes * 8} "
                     f"(nprobes {nprobes} x f64)")
        m.probes = np.frombuffer(f, dtype="<f8")
    if text:
        t = frames[-1]
        if len(t) > MAX_TEXT:
            _fail(m, f"text frame is {len(t)} bytes, at most {MAX_TEXT}")
        if b"\0" in t:
            _fail(m, f"text frame has a NUL byte at offset {t.index(0)}")
        try:
            m.text = t.decode("utf-8")  # strict: rejects overlongs, surrogates, > U+10FFFF
        except UnicodeDecodeError as e:
            _fail(m, f"text is not valid UTF-8 at byte {e.start}")
    _check(m, dim)
    return m


def capabilities(hello_text: str) -> set:
    """The capability names a HELLO declares (PROTOCOL.md 4: caps=a,b; absent means none)."""
    caps = _kv(hello_text or "", " ").get("caps", "")
    return {c for c in caps.split(",") if c}


class Rollback:
    """The solver's side of implicit coupling (PROTOCOL.md 6): call check()
    with every ADVANCE before stepping. It says whether the step starts
    (iteration 0: keep your state now) or repeats the previous one
    (iteration > 0: return to the kept state), and raises ProtocolError for an
    ADVANCE that may not come (a repeat without rollback=on in CONFIG, or
    one that is not the previous step's next iteration)."""

    def __init__(self, enabled: bool):
        self.enabled = enabled
        self.last = None   # (step, iteration, time, dt, n_sub) of the previous ADVANCE

    def check(self, m: Message) -> str:
        """'new' (iteration 0) or 'repeat'."""
        prev, self.last = self.last, (m.step, m.iteration, m.time, m.dt, m.n_sub)
        if m.iteration == 0:
            return "new"
        if not self.enabled:
            raise ProtocolError(f"ADVANCE step {m.step} iteration {m.iteration}: a repeated "
                                "step needs rollback=on in CONFIG")
        if prev is None or (m.step, m.iteration - 1, m.time, m.dt, m.n_sub) != prev:
            raise ProtocolError(f"ADVANCE step {m.step} iteration {m.iteration} at t = {m.time!r}, "
                                f"dt = {m.dt!r}, n_sub {m.n_sub} does not repeat the previous "
                                f"ADVANCE {prev}")
        return "repeat"


def error_status(text: str) -> tuple:
    """('diverged', 'x = nan') from an ERROR text; ('peer', text) if it has no status."""
    for s in STATUS_NAMES:
        if text.startswith(s + ": "):
            return s, text[len(s) + 2:]
    return "peer", text


# ---- frame files (PROTOCOL.md appendix A) ----

def write_frames(path, frames) -> None:
    with open(path, "wb") as f:
        f.write(b"MPSF" + struct.pack("<I", len(frames)))
        for fr in frames:
            f.write(struct.pack("<Q", len(fr)))
            f.write(bytes(fr))


def read_frames(path) -> list:
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] != b"MPSF":
        raise ValueError(f"{path}: not a frame file")
    (n,), pos, out = struct.unpack_from("<I", data, 4), 8, []
    for _ in range(n):
        (ln,) = struct.unpack_from("<Q", data, pos)
        pos += 8
        out.append(data[pos:pos + ln])
        pos += ln
    return out


# ---- ZeroMQ link (PROTOCOL.md sections 1 and 7) ----

# ---- CURVE keys (PROTOCOL.md section 10) ----

KEY_ENV = "MPS_COUPLING_KEY"
KEY_FIELDS = ("server_public", "client_public", "client_secret")


def read_key(path) -> dict:
    """A solver's key file: {'server_public', 'client_public', 'client_secret'}
    as Z85 bytes. ValueError (naming file and line) for a file others may
    read, a missing, repeated or unknown name, a value that is not a 40-char
    Z85 key, or a public key that does not belong to the secret one."""
    import os
    import stat
    import zmq
    from zmq.utils import z85
    st = os.stat(path)
    if not stat.S_ISREG(st.st_mode):
        raise ValueError(f"{path}: the key file is not a regular file")
    if st.st_mode & 0o077:
        raise ValueError(f"{path}: the key file has mode {stat.S_IMODE(st.st_mode):04o}, "
                         f"others may read it: chmod 600 {path}")
    keys = {}
    with open(path, "rb") as f:
        data = f.read(4097)
    if len(data) > 4096 or b"\0" in data:
        raise ValueError(f"{path}: not a key file")
    for n, line in enumerate(data.decode("ascii", "replace").split("\n"), 1):
        line = line.rstrip("\r")
        if not line or line.startswith("#"):
            continue
        name, eq, value = line.partition("=")
        if not eq or name not in KEY_FIELDS:
            raise ValueError(f"{path}:{n}: expected server_public=, client_public= or "
                             f"client_secret=, got '{line[:40]}'")
        if name in keys:
            raise ValueError(f"{path}:{n}: {name} given twice")
        if len(value) != 40:
            raise ValueError(f"{path}:{n}: {name} is {len(value)} characters, a Z85 key has 40")
        try:
            z85.decode(value.encode())
        except (ValueError, KeyError, IndexError) as e:
            raise ValueError(f"{path}:{n}: {name} is not a Z85 key") from e
        keys[name] = value.encode()
    for name in KEY_FIELDS:
        if name not in keys:
            raise ValueError(f"{path}: {name} missing")
    if zmq.curve_public(keys["client_secret"]) != keys["client_public"]:
        raise ValueError(f"{path}: client_public does not belong to client_secret")
    return keys


def connect(ctx, endpoint: str, key_file=None):
    """A solver's DEALER socket, connected, with the protocol's linger and send
    timeout. A tcp endpoint is a CURVE client with the keys of key_file (or of
    the file named by the environment variable MPS_COUPLING_KEY, which the
    coupler sets for the solvers it launches); ProtocolError if there is none."""
    import os
    import zmq
    s = ctx.socket(zmq.DEALER)
    s.setsockopt(zmq.LINGER, LINGER_MS)
    s.setsockopt(zmq.SNDTIMEO, SEND_TIMEOUT_MS)
    if endpoint.startswith("tcp://"):
        key_file = key_file or os.environ.get(KEY_ENV)
        if not key_file:
            s.close(0)
            raise ProtocolError(f"{endpoint}: a tcp endpoint needs the run's key: --key FILE "
                                f"(or {KEY_ENV}=FILE in the environment; PROTOCOL.md section 10)")
        try:
            k = read_key(key_file)
        except (OSError, ValueError):
            s.close(0)
            raise
        s.setsockopt(zmq.HANDSHAKE_IVL, 5000)
        s.curve_serverkey = k["server_public"]
        s.curve_publickey = k["client_public"]
        s.curve_secretkey = k["client_secret"]
    s.connect(endpoint)
    return s


def send(sock, m: Message) -> None:
    """Encodes (raising ProtocolError) and sends one multipart message;
    zmq.Again if it cannot be queued within the send timeout."""
    sock.send_multipart(encode(m), copy=True)


def recv(sock, timeout_ms: int) -> Message:
    """Waits up to timeout_ms for one message; TimeoutError after the deadline,
    ProtocolError if it is malformed (it is consumed)."""
    import zmq
    if not sock.poll(timeout_ms, zmq.POLLIN):
        raise TimeoutError(f"no message within {timeout_ms} ms")
    return decode(sock.recv_multipart(copy=True))


# ---- a solver's own case keys (PROTOCOL.md 4 and 8, "Case error") ----

CASE_ERROR = "case: "
RESOLVED_INTRO = "# Resolved from "
RESOLVED_TAIL = " (defaults filled in, --set applied)"
ORIGIN_MARK = "#@ "


def case_error(text: str):
    """The LINE of an ERROR text "input: case: LINE", or None for any other text."""
    status, message = error_status(text)
    if status == "input" and message.startswith(CASE_ERROR):
        return message[len(CASE_ERROR):]
    return None


class CaseError(Exception):
    """One of the solver's case keys is wrong. str(e) is the one line
    "WHERE: KEY = VALUE: problem"; the solver sends ERROR
    "input: case: " + str(e) and exits 2, and the coupler prints the line as
    its own."""


class Case:
    """A case file as flat dotted keys ("solid.bodies.0.E"), each with where
    it was given: for the coupler's resolved copy, the user's "case.yml:LINE"
    or "--set KEY=VALUE" from its "#@ KEY<TAB>WHERE<TAB>VALUE" lines (while
    the copy still holds that value), else this file's line. Values are the
    scalars as written; the getters check them and raise CaseError."""

    def __init__(self, path: str):
        import yaml  # only solvers that read the case need PyYAML

        with open(path) as f:
            text = f.read()
        lines = text.splitlines()
        first = lines[0] if lines else ""
        resolved = first.startswith(RESOLVED_INTRO)
        # a key that is missing is named in the user's file, as the coupler would
        self.file = first[len(RESOLVED_INTRO):-len(RESOLVED_TAIL)] \
            if resolved and first.endswith(RESOLVED_TAIL) else path
        self.values, self.where = {}, {}
        try:
            root = yaml.compose(text)
        except yaml.YAMLError as e:
            mark = getattr(e, "problem_mark", None)
            raise CaseError(f"{path}:{mark.line + 1 if mark else 0}: YAML syntax error: "
                            f"{getattr(e, 'problem', e)}") from e
        if root is not None:
            self._flatten(root, "", path)
        for line in lines if resolved else ():
            if line.startswith(ORIGIN_MARK):
                parts = line[len(ORIGIN_MARK):].split("\t")
                if len(parts) == 3 and self.values.get(parts[0]) == parts[2]:
                    self.where[parts[0]] = parts[1]

    def _flatten(self, node, prefix, path):
        import yaml

        if isinstance(node, yaml.MappingNode):
            for k, v in node.value:
                self._flatten(v, f"{prefix}.{k.value}" if prefix else str(k.value), path)
        elif isinstance(node, yaml.SequenceNode):
            for i, v in enumerate(node.value):
                self._flatten(v, f"{prefix}.{i}", path)
        else:
            self.values[prefix] = node.value
            self.where[prefix] = f"{path}:{node.start_mark.line + 1}"

    def has(self, key: str) -> bool:
        return key in self.values

    def count(self, prefix: str) -> int:
        """Items of the sequence at prefix: 1 + the largest index given."""
        idx = [int(k[len(prefix) + 1:].split(".")[0]) for k in self.values
               if k.startswith(prefix + ".") and k[len(prefix) + 1:].split(".")[0].isdigit()]
        return max(idx) + 1 if idx else 0

    def fail(self, key: str, problem: str):
        """Raises the CaseError "WHERE: KEY = VALUE: problem" for key."""
        if key in self.values:
            shown = self.values[key] if self.values[key] != "" else "(empty)"
            raise CaseError(f"{self.where[key]}: {key} = {shown}: {problem}")
        raise CaseError(f"{self.file}: {key}: {problem}")

    def number(self, key: str, default=None, lo=None, lo_open=False, hi=None, hi_open=False):
        """The value of key as a finite number within the bounds given (as the
        C solvers word them: "must be > 0", "must be in (0, 1]")."""
        if key not in self.values:
            if default is None:
                raise CaseError(f"{self.file}: missing required key '{key}'")
            return float(default)
        try:
            v = float(self.values[key])
        except ValueError:
            self.fail(key, "must be a number")
        if not math.isfinite(v):
            self.fail(key, "must be a finite number")
        low = lo is not None and (v <= lo if lo_open else v < lo)
        high = hi is not None and (v >= hi if hi_open else v > hi)
        if low or high:
            if hi is None:
                self.fail(key, f"must be {'>' if lo_open else '>='} {lo:g}")
            if lo is None:
                self.fail(key, f"must be {'<' if hi_open else '<='} {hi:g}")
            self.fail(key, f"must be in {'(' if lo_open else '['}{lo:g}, {hi:g}"
                           f"{')' if hi_open else ']'}")
        return v

    def only(self, prefix: str, known):
        """Refuses a key under prefix (a section the solver owns) that is not
        one of known: "unknown key", with the nearest as a suggestion."""
        import difflib

        for key in self.values:
            if key.startswith(prefix) and key not in known:
                near = difflib.get_close_matches(key, list(known), n=1, cutoff=0.8)
                self.fail(key, "unknown key" + (f"; did you mean {near[0]}?" if near else ""))
