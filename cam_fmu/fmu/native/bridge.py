"""The Python half of cam.fmu's own linux64 binary (copied into the FMU as ``<private package>._fmi_bridge``).

The C wrapper (``fmi2_python.c``) calls only into this module. Everything here
runs with the GIL held by the caller. Protocol:

- every ``Instance`` method returns ``(status, payload, messages)``: ``status`` an
  FMI status (0 OK ... 4 fatal), ``payload`` the result (bytes of packed values,
  a state object, ...), ``messages`` ``None`` or a list of
  ``(status, category, text)`` for the FMI logger;
- a Python exception raised by a slave method becomes fmi2Error (category
  ``logStatusError``), or fmi2Discard (``logStatusDiscard``) when the exception
  has ``fmi_status == "discard"``; its text is logged and kept in ``last_error``;
- an exception escaping *this* module means the interpreter is broken: the C
  side reports fmi2Fatal.

Values cross the boundary packed (``array`` bytes): fmi2GetReal/fmi2SetReal of n
variables is one Python call, not n.

The exchange (``Exchange``): a slave that names its per-step variables
(``exchange_layout``) gets a ``bytearray`` the C side also reads. After every
call this module publishes the slave's outputs and inputs into it; fmi2GetReal
of those variables and fmi2SetReal of inputs within their ranges are then
answered in C without the GIL, and inputs C wrote are handed to the slave before
the next call. Everything else, and every value out of range, comes here.
Python owns the buffer (C keeps a reference), so Python holds no pointer into
the library.

Isolation: the private package and the slave module are imported from their
files by name (``importlib``), without ever touching ``sys.path``; ``unload``
takes exactly the ``sys.modules`` names they added away again after the last
instance was freed (``detach``) and puts them back for the next one (``attach``).
"""
from __future__ import annotations

import importlib
import importlib.util
import os
import sys
from array import array

OK, WARNING, DISCARD, ERROR, FATAL = 0, 1, 2, 3, 4
_CATEGORY = {WARNING: "logStatusWarning", DISCARD: "logStatusDiscard", ERROR: "logStatusError",
             FATAL: "logStatusFatal"}

_added_modules: set = set()
# "no messages": an empty list, never mutated (the C side reads it with PyList_Size; None would make
# that call raise and clear a TypeError on every FMI call, ~1 us each)
_NO_MESSAGES: list = []


def _own_names(package: str, slave_module: str):
    return [name for name in list(sys.modules)
            if name == slave_module or name == package or name.startswith(package + ".")]


def load(package: str, slave_module: str, resources: str):
    """Import the slave module (a private top-level name) from ``resources`` and return its Fmi2Slave class."""
    before = set(sys.modules)
    path = os.path.join(resources, slave_module + ".py")
    module = sys.modules.get(slave_module)
    if module is None:
        spec = importlib.util.spec_from_file_location(slave_module, path)
        if spec is None:
            raise ImportError(f"no slave module at {path}")
        module = importlib.util.module_from_spec(spec)
        sys.modules[slave_module] = module
        try:
            spec.loader.exec_module(module)
        except BaseException:
            sys.modules.pop(slave_module, None)
            raise
    _added_modules.update(set(_own_names(package, slave_module)) - before)
    base = importlib.import_module(package + "._pythonfmu.fmi2slave").Fmi2Slave
    classes = [obj for obj in vars(module).values()
               if isinstance(obj, type) and issubclass(obj, base) and obj is not base
               and obj.__module__ == module.__name__]
    if len(classes) != 1:
        raise ImportError(f"{slave_module} defines {len(classes)} Fmi2Slave subclasses, expected exactly 1")
    return classes[0]


_detached: dict = {}


def detach(package: str, slave_module: str) -> int:
    """After the last instance was freed: take this FMU's names out of sys.modules; return how many.

    The C side keeps the bridge and the slave class, so the next fmi2Instantiate calls
    ``attach`` instead of importing everything again (fast, and nothing to leak)."""
    names = _own_names(package, slave_module)
    for name in names:
        _detached[name] = sys.modules.pop(name)
    return len(names)


def attach() -> int:
    """Put the names taken away by ``detach`` back into sys.modules (lazy relative imports need them)."""
    count = 0
    for name, module in _detached.items():
        if name not in sys.modules:
            sys.modules[name] = module
            count += 1
    _detached.clear()
    return count


_EXCHANGE_MAGIC = 0x58434D43  # "CMCX": the C side checks it before it trusts the layout
# the exchange's header, int32 each, in this order (the C side reads these names' positions: fmi2_python.c)
_HEAD = ("magic", "n_out", "n_in", "off_vr", "off_lo", "off_hi", "off_value", "ready", "dirty")
_READY, _DIRTY = _HEAD.index("ready"), _HEAD.index("dirty")


class Exchange:
    """The per-step variables in one buffer shared with the C side (layout described by its header).

    Slots: the outputs, then the inputs. ``vr`` their value references (uint32), ``lo``/``hi``
    the allowed range of each input (C checks a value against it, an out-of-range value goes to
    Python for its message), ``value`` the current values (double). ``ready``: the outputs are
    published; ``dirty``: C wrote inputs the slave has not seen yet.
    """

    def __init__(self, output_vrs, input_vrs, input_ranges) -> None:
        self.n_out, n = len(output_vrs), len(output_vrs) + len(input_vrs)
        off_vr = 4 * len(_HEAD)
        off_lo = (off_vr + 4 * n + 7) // 8 * 8
        off_hi, off_value = off_lo + 8 * n, off_lo + 16 * n
        self.buffer = bytearray(off_value + 8 * n)
        view = memoryview(self.buffer)
        self.head = view[:off_vr].cast("i")
        self.head[:] = array("i", [_EXCHANGE_MAGIC, self.n_out, n - self.n_out, off_vr, off_lo, off_hi, off_value,
                                   0, 0])
        view[off_vr:off_vr + 4 * n].cast("I")[:] = array("I", list(output_vrs) + list(input_vrs))
        unbounded = [(-float("inf"), float("inf"))] * self.n_out  # outputs are never set
        bounds = unbounded + [(float(lo), float(hi)) for lo, hi in input_ranges]
        view[off_lo:off_hi].cast("d")[:] = array("d", [lo for lo, _ in bounds])
        view[off_hi:off_value].cast("d")[:] = array("d", [hi for _, hi in bounds])
        values = view[off_value:].cast("d")
        self.outputs, self.inputs = values[:self.n_out], values[self.n_out:]

    def hand_inputs(self, slave) -> None:
        """Give the slave the inputs C wrote (already checked against their ranges)."""
        self.head[_DIRTY] = 0
        slave.take_inputs(self.inputs.tolist())

    def publish(self, slave, inputs: bool = True) -> None:
        """Copy the slave's published outputs and its inputs in (``ready`` only when it has outputs).

        ``inputs=False`` after a successful step: a slave's do_step does not change its inputs."""
        outputs = slave.published_outputs()
        if outputs is None:
            self.head[_READY] = 0
        else:
            self.outputs[:] = outputs
            self.head[_READY] = 1
        if inputs:
            self.inputs[:] = slave.input_values()


def _text(exc: BaseException) -> str:
    text = str(exc)
    if type(exc).__module__.split(".")[0] in {"builtins"} or not text:
        text = f"{type(exc).__name__}: {text}" if text else type(exc).__name__
    return text


class Instance:
    """One FMU instance: the slave object and the conversions around it."""

    def __init__(self, cls, name: str, resources: str, visible: bool):
        self.cls = cls
        cls.errors_reach_logger = True  # this binary logs every error through the host's logger (docs/fmu.md)
        self.args = dict(instance_name=name, resources=resources, visible=bool(visible))
        self.slave = None
        self.last_error = ""
        self.strings = ()  # keeps the bytes returned by the last get_string alive
        self.exchange: Exchange | None = None  # made at the first create of a slave that has a layout

    # ------------------------------------------------------------ plumbing
    def _drain(self, extra=None):
        messages = _NO_MESSAGES
        slave = self.slave
        queue = getattr(slave, "log_queue", None) if slave is not None else None
        if queue:
            messages = [(int(m.status), m.category or "logAll", str(m.msg)) for m in queue]
            del queue[:]
        if extra is not None:
            status, text = extra
            # the slave may have logged the same text before raising: report it once, with the call's status
            messages = [m for m in (messages or ()) if m[2] != text]
            messages.append((status, _CATEGORY[status], text))
        return messages

    def _run(self, fn, *args):
        exchange = self.exchange
        if exchange is not None and exchange.head[_DIRTY]:
            exchange.hand_inputs(self.slave)
        try:
            payload = fn(*args)
        except Exception as exc:  # noqa: BLE001 - every slave exception is a status for the importer
            return self._failed(exc)
        if exchange is not None:
            exchange.publish(self.slave)
        return OK, payload, self._drain()

    def _failed(self, exc: Exception):
        """The status and messages of a slave exception (fmi2Discard when it says so, else fmi2Error)."""
        status = DISCARD if getattr(exc, "fmi_status", None) == "discard" else ERROR
        self.last_error = _text(exc)
        if self.exchange is not None and self.slave is not None:
            self.exchange.publish(self.slave)  # a failed call may have changed some values
        return status, None, self._drain((status, self.last_error))

    def share(self):
        """The exchange's buffer for the C side (after ``create``), or None: this slave has no layout."""
        layout = getattr(self.slave, "exchange_layout", None)
        if layout is None:
            return OK, None, self._drain()
        status, payload, messages = self._run(layout)
        if status == OK:
            self.exchange = Exchange(*payload)
            self.exchange.publish(self.slave)
            payload = self.exchange.buffer
        return status, payload, messages

    # ------------------------------------------------------------ life cycle
    def create(self):
        def make():
            self.slave = self.cls(**self.args)
        return self._run(make)

    reset = create

    def setup_experiment(self, start, stop_defined, stop, tolerance_defined, tolerance):
        return self._run(lambda: self.slave.setup_experiment(start, stop if stop_defined else None,
                                                             tolerance if tolerance_defined else None))

    def enter_initialization_mode(self):
        return self._run(lambda: self.slave.enter_initialization_mode())

    def exit_initialization_mode(self):
        return self._run(lambda: self.slave.exit_initialization_mode())

    def terminate(self):
        return self._run(lambda: self.slave.terminate())

    def do_step(self, time, step):
        """The per-step call, written out (``_run``'s steps without its generality): a slave's do_step
        changes no input, so only the outputs are published."""
        slave, exchange = self.slave, self.exchange
        if exchange is not None and exchange.head[_DIRTY]:
            exchange.hand_inputs(slave)
        try:
            done = slave.do_step(time, step)
        except Exception as exc:  # noqa: BLE001
            return self._failed(exc)
        if not done:
            self.last_error = f"do_step({time!r}, {step!r}) returned {done!r}: step discarded"
            return DISCARD, None, self._drain((DISCARD, self.last_error))
        if exchange is not None:
            exchange.publish(slave, inputs=False)
        return OK, None, self._drain()

    # ------------------------------------------------------------ values
    def get_real(self, vrs: bytes):
        packed = getattr(self.slave, "get_real_packed", None)  # a slave's fast path for its outputs
        if packed is not None:
            status, payload, messages = self._run(packed, vrs)
            if status != OK or payload is not None:
                return status, payload, messages
        return self._run(lambda: array("d", self.slave.get_real(array("I", vrs).tolist())).tobytes())

    def set_real(self, vrs: bytes, values: bytes):
        packed = getattr(self.slave, "set_real_packed", None)  # a slave's fast path for its inputs
        if packed is not None:
            status, payload, messages = self._run(packed, vrs, values)
            if status != OK or payload:
                return status, None, messages
        return self._run(lambda: self.slave.set_real(array("I", vrs).tolist(), array("d", values).tolist()))

    def get_integer(self, vrs: bytes):
        return self._run(lambda: array("i", self.slave.get_integer(array("I", vrs).tolist())).tobytes())

    def set_integer(self, vrs: bytes, values: bytes):
        return self._run(lambda: self.slave.set_integer(array("I", vrs).tolist(), array("i", values).tolist()))

    def get_boolean(self, vrs: bytes):
        return self._run(lambda: array("i", [1 if v else 0 for v in
                                             self.slave.get_boolean(array("I", vrs).tolist())]).tobytes())

    def set_boolean(self, vrs: bytes, values: bytes):
        return self._run(lambda: self.slave.set_boolean(array("I", vrs).tolist(),
                                                        [v != 0 for v in array("i", values)]))

    def get_string(self, vrs: bytes):
        def get():
            self.strings = tuple(str(s).encode("utf-8") for s in self.slave.get_string(array("I", vrs).tolist()))
            return self.strings
        return self._run(get)

    def set_string(self, vrs: bytes, joined: bytes):
        """``joined``: the values, each followed by a NUL byte."""
        values = [v.decode("utf-8") for v in joined.split(b"\0")[:-1]]
        return self._run(lambda: self.slave.set_string(array("I", vrs).tolist(), values))

    # ------------------------------------------------------------ state
    def get_state(self):
        return self._run(lambda: self.slave._get_fmu_state())

    def set_state(self, state):
        return self._run(lambda: self.slave._set_fmu_state(state))

    def state_to_bytes(self, state):
        return self._run(lambda: bytes(self.cls._fmu_state_to_bytes(state)))

    def state_from_bytes(self, data: bytes):
        return self._run(lambda: self.cls._fmu_state_from_bytes(data))
