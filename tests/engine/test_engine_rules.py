"""The cross-parameter rules (physics/rules.py RULES): the C engine (cam_check_rules, generated from the table by
engine/codegen.py) and the Python model (DriveModel, which interprets the table) refuse the same parameter sets
with the same message, and accept the same ones. The cases are generated from the table: every parameter a rule
reads takes each of its choices, or 0 and a value inside its range, at random from a fixed seed; each rule is
met at least once, and so are parameter sets no rule refuses."""
from __future__ import annotations

import ctypes
import random

import pytest

from cam_fmu.engine.simulator import CamError, DriveSimulator, _set_parameter, engine
from cam_fmu.physics import rules
from cam_fmu.physics.drive import DriveModel, own_follower
from cam_fmu.physics.parameters import ARM_TRAIN_PARAMETERS, BY_NAME, FOLLOWER_KIND_PARAMETERS, ParameterError, resolve

PER_RULE = 3       # cases kept for each rule
ACCEPTED = 12      # and parameter sets no rule refuses
DRAWS = 40000     # the follower kind's eight fields make the later rules' cases rare (the last one met at 40000)
KIND_FIELDS = FOLLOWER_KIND_PARAMETERS + ARM_TRAIN_PARAMETERS   # the kind's, and an arm's train's


def candidates(name: str) -> list:
    """The values a case gives parameter `name`: its choices, false/true, or 0 (if allowed) and an inside value."""
    spec = BY_NAME[name]
    if spec.kind == "string":
        return list(spec.choices)
    if spec.kind == "boolean":
        return [False, True]
    inside = spec.default if spec.default != 0.0 else (spec.low * 10.0 if spec.low > 0.0 else min(spec.high, 1.0) / 2)
    return [0.0, inside] if spec.zero_ok or spec.low == 0.0 else [inside]


def kind_fields(rng: random.Random, params: dict) -> dict:
    """The follower kind's fields of a case: drawn alone they would nearly always break a kind rule and hide the
    later rules, so a third of the cases take the default kind, a third a type with the fields it needs (an arm's
    three inside their ranges but for one in six, a translating type's all at 0), a third the drawn type with one field
    drawn."""
    draw = rng.random()
    if draw < 1 / 3:
        return {p.name: p.default for p in KIND_FIELDS}
    if draw < 2 / 3:
        kind = params["follower_type"]
        arm = kind.startswith("oscillating")
        needed = ("arm_length", "pivot_distance", "lift_angle")   # each set, or now and then missing
        return {p.name: (rng.choice(candidates(p.name)[-1:] * 5 + [0.0]) if arm and p.name in needed
                         else params[p.name] if arm else p.default) for p in KIND_FIELDS
                if p.name != "follower_type"}
    one = rng.choice([p.name for p in KIND_FIELDS if p.name != "follower_type"])
    return {p.name: params[p.name] if p.name == one else p.default for p in KIND_FIELDS
            if p.name != "follower_type"}


def cases() -> list[tuple[int | None, dict]]:
    """(index of the first rule that refuses, or None; parameters) for every kept case."""
    names = sorted(rules.rule_names())
    rng = random.Random(38)
    kept: dict[int | None, list[dict]] = {}
    for _ in range(DRAWS):
        params = {name: rng.choice(candidates(name)) for name in names}
        params.update(kind_fields(rng, params))
        p = resolve(params)
        first = next((k for k, rule in enumerate(rules.RULES) if rule.when.value(p)), None)
        bucket = kept.setdefault(first, [])
        if len(bucket) < (ACCEPTED if first is None else PER_RULE) and params not in bucket:
            bucket.append(params)
    return [(k, params) for k, bucket in sorted(kept.items(), key=lambda kv: -1 if kv[0] is None else kv[0])
            for params in bucket]


CASES = cases()


def test_every_rule_is_met():
    """The generated cases reach every rule of the table, and parameter sets that pass them all."""
    met = {k for k, _ in CASES}
    assert met == set(range(len(rules.RULES))) | {None}


def refusal(make, params: dict) -> str | None:
    try:
        make(params)
    except ParameterError as exc:
        return str(exc)
    return None


@pytest.mark.parametrize("index,params", CASES, ids=[f"rule{k}-{n}" for n, (k, _) in enumerate(CASES)])
def test_c_and_python_refuse_alike(index, params):
    """The C engine and the Python model give the table's message for a refused case, nothing for an accepted
    one; the message names a parameter the rule reads."""
    expected = None if index is None else rules.RULES[index].text(resolve(params))
    assert refusal(DriveModel, params) == expected
    assert refusal(DriveSimulator, params) == expected
    if expected is not None:
        assert expected.startswith("parameter") and any(f"'{name}'" in expected
                                                         for name in rules.RULES[index].when.names())


def c_own_follower(params: dict) -> bool:
    """The generated cam_own_follower over a CamParams set through the binding (its v[] is the struct's start)."""
    lib = engine()
    function = lib.cam_own_follower
    function.restype, function.argtypes = ctypes.c_int, [ctypes.c_void_p]
    raw = ctypes.create_string_buffer(lib.cam_params_sizeof())
    lib.cam_params_defaults(raw)
    err = CamError()
    try:
        for name, value in params.items():
            _set_parameter(lib, raw, name, value, err)
        return bool(function(raw))
    finally:
        lib.cam_params_free(raw)


@pytest.mark.parametrize("index,params", CASES, ids=[f"rule{k}-{n}" for n, (k, _) in enumerate(CASES)])
def test_own_follower_alike(index, params):
    """rules.OWN_FOLLOWER generated into C (model.c's free_follower) and interpreted in Python agree, refused or
    not; a model the rules accept carries it."""
    expected = own_follower(resolve(params))
    assert c_own_follower(params) == expected
    if index is None:
        assert DriveModel(params).free_follower == expected
