"""A trained PPO / RecurrentPPO policy behind the common ``predict`` interface (``ppo:<path>``).

``path`` is one of:

* the ``model.zip`` a training run saved (or a folder holding it), with ``ppo_meta.json`` beside it;
* a *packed* SB3 zip (:func:`pack_policy`: ``ppo_meta.json`` inside, a fresh optimizer);
* a **pickle-free policy file** (``.npz``, :func:`pack_npz`): the actor's weights as ``.npy`` arrays
  plus ``policy.json``, a JSON record of the architecture (layers, activations, action bounds) and of
  the training meta (belief features, hand action, observation normalisation). This is what the
  leaderboard keeps (format ``ppo-npz``).

The meta gives the algorithm, the belief features and hand action used in training, and the
observation normalisation statistics, which this agent applies itself (no pickled VecNormalize).

**Pickles.** An SB3 ``.zip`` is *not* pickle-free: loading one unpickles (cloudpickle) the objects in
its ``data`` member, so ``ppo:<model.zip>`` must only be given files you trust, e.g. your own training
runs. A ``.npz`` policy loads with ``allow_pickle=False`` and no ``torch.load``: the actor is rebuilt
as a ``torch.nn.Sequential`` from ``policy.json`` and the arrays are copied into it.
:func:`pack_npz` converts a trusted SB3 PPO model and proves that the rebuilt actor gives the SB3
model's deterministic actions, bit for bit, on sampled observations.
"""

from __future__ import annotations

import io
import json
import math
import zipfile
from pathlib import Path

import numpy as np

META_NAME = "ppo_meta.json"

# ---- the pickle-free policy file (format "ppo-npz")
NPZ_FORMAT = "ppo-npz"
NPZ_FORMAT_VERSION = 1
NPZ_RECORD = "policy.json"
# Modelling choices bounding what a policy file may make the loader read (a zip can claim any size):
# the committed policies are ~0.7 MB with 6 arrays; 64 MiB and 64 members leave room for much larger
# MLPs while refusing zip bombs before anything is decompressed.
NPZ_MAX_BYTES = 64 * 1024 * 1024
NPZ_MAX_MEMBERS = 64
# A budget on the network a policy file builds, checked from policy.json and the .npy headers before any
# array is read or any layer allocated (a small file may name one large array from many layers).
# Modelling choice: the committed ppo-npz policies have 3 layers, 6 arrays, 87,562 parameters and
# 174,080 FLOPs per action (2 x multiply-adds); each bound leaves 40x or more room above them.
NPZ_MAX_PARAMETERS = 4_000_000  # 46x; 16 MB of float32
NPZ_MAX_LAYERS = 16  # 5x
NPZ_MAX_WIDTH = 4096  # inputs or outputs of one layer (committed: 256)
NPZ_MAX_FLOPS = 8_000_000  # per action, 46x (~ms on one CPU core)
NPZ_MAX_RECORD_BYTES = 1024 * 1024  # policy.json (committed: ~5 KB)
# meta scalars: key -> (type, low, high); None: no bound. Ranges are modelling choices around training's
# values (clip 10, epsilon 1e-8, residuals 0.15 m and 3 deg) wide enough for any sensible setting.
NPZ_META_NUMBERS = {
    "clip_obs": (float, 1e-3, 1e3),
    "epsilon": (float, 0.0, 1.0),
    "intercept_residual_m": (float, 0.0, 10.0),
    "gaze_residual_deg": (float, 0.0, 90.0),
    "gaze_log_std_init": (float, -10.0, 2.0),
    "eye_head_log_std_init": (float, -10.0, 2.0),
    "seed": (int, 0, None),
    "timesteps": (int, 0, None),
    "train_wall_s": (float, 0.0, None),
}
NPZ_META_STRINGS = ("algo", "env_id", "hand_action", "gaze_action")
NPZ_META_BOOLS = ("belief",)
# RecurrentPPO (format "ppo-npz" with ``network.kind = "lstm_mlp"``): the actor's one-layer LSTM as four
# arrays named in ``network.lstm`` (PyTorch's nn.LSTM layout: gates i, f, g, o stacked along rows).
NPZ_LSTM_ARRAYS = ("weight_ih", "weight_hh", "bias_ih", "bias_hh")
# SAC (format "ppo-npz" with ``network.squash = "tanh"``): the actor's mean goes through tanh and is rescaled
# from [-1, 1] to [action_low, action_high] (SB3's squashed Gaussian mode and ``unscale_action``), not clipped.
NPZ_SQUASH = (None, "tanh")
NPZ_ACTIVATIONS = ("tanh", "relu", "elu", "leaky_relu", "silu", "gelu", "sigmoid")
# Observations on which pack_npz proves the rebuilt actor equal to the SB3 model (modelling choice:
# 2000 single-observation calls take well under a second and cover the clipped normalised range).
NPZ_PROOF_OBSERVATIONS = 2000
# A recurrent actor is proven on one stream of observations with a new episode every 100 steps (modelling
# choice: each state carried across ~100 steps and reset ~20 times in the default 2000).
NPZ_PROOF_EPISODE = 100
_ZIP_DATE = (1980, 1, 1, 0, 0, 0)  # fixed member dates: the same model packs to the same bytes


def resolve(path: str | Path) -> tuple[Path, Path | None]:
    """(model zip, meta json) for a run folder or a model file; meta None when packed in the zip."""
    p = Path(path)
    model = p / "model.zip" if p.is_dir() else p
    if not model.is_file():
        raise FileNotFoundError(f"no PPO model at {model} (give a model .zip or a run folder holding model.zip)")
    meta = model.with_name(META_NAME)
    if not meta.is_file():
        meta = model.with_suffix(".meta.json")
    if not meta.is_file():
        if _packed_meta(model.read_bytes()) is not None:
            return model, None
        raise FileNotFoundError(f"{model} has no {META_NAME} (or {model.stem}.meta.json) beside it or inside it")
    return model, meta


def _packed_meta(data: bytes) -> dict | None:
    try:
        with zipfile.ZipFile(io.BytesIO(data)) as zf:
            if META_NAME not in zf.namelist():
                return None
            return json.loads(zf.read(META_NAME).decode("utf-8"))
    except zipfile.BadZipFile:
        return None


def _algo_class(algo: str):
    if algo == "RecurrentPPO":
        from sb3_contrib import RecurrentPPO

        return RecurrentPPO
    if algo == "PPO":
        from stable_baselines3 import PPO

        return PPO
    if algo == "SAC":
        from stable_baselines3 import SAC

        return SAC
    raise ValueError(f"unknown algo {algo!r} in {META_NAME} (PPO, RecurrentPPO or SAC)")


def pack_policy(path: str | Path) -> bytes:
    """One self-contained policy file for a trained run: the SB3 zip with a fresh (empty) optimizer
    state, which inference never uses, and ``ppo_meta.json`` inside; loadable as ``ppo:<file>``."""
    model_path, meta_path = resolve(path)
    if meta_path is None:
        return model_path.read_bytes()  # already packed
    meta = json.loads(meta_path.read_text())
    model = _algo_class(meta["algo"]).load(model_path, device="cpu")
    policy = model.policy
    policy.optimizer = policy.optimizer_class(policy.parameters(), lr=float(model.lr_schedule(1.0)),
                                              **policy.optimizer_kwargs)
    buf = io.BytesIO()
    model.save(buf)
    with zipfile.ZipFile(buf, "a", compression=zipfile.ZIP_DEFLATED) as zf:
        info = zipfile.ZipInfo(META_NAME, date_time=(1980, 1, 1, 0, 0, 0))
        zf.writestr(info, json.dumps(meta, indent=2, sort_keys=True))
    return buf.getvalue()


# ------------------------------------------------------------------ pickle-free policy (ppo-npz)


class PolicyFileError(ValueError):
    """A ``ppo-npz`` policy file is malformed; the message says what is wrong."""


def _activation_name(module) -> str:
    import torch.nn as nn

    names = {nn.Tanh: "tanh", nn.ReLU: "relu", nn.ELU: "elu", nn.LeakyReLU: "leaky_relu", nn.SiLU: "silu",
             nn.GELU: "gelu", nn.Sigmoid: "sigmoid"}
    for cls, name in names.items():
        if type(module) is cls:
            if cls is nn.LeakyReLU and module.negative_slope != 0.01:
                break
            if cls is nn.ELU and module.alpha != 1.0:
                break
            if cls is nn.GELU and module.approximate != "none":
                break
            return name
    raise ValueError(f"activation {module!r} has no pickle-free form (known: {', '.join(NPZ_ACTIVATIONS)})")


def _activation_module(name: str):
    import torch.nn as nn

    table = {"tanh": nn.Tanh, "relu": nn.ReLU, "elu": nn.ELU, "leaky_relu": nn.LeakyReLU, "silu": nn.SiLU,
             "gelu": nn.GELU, "sigmoid": nn.Sigmoid}
    if name not in table:
        raise PolicyFileError(f"unknown activation {name!r} (known: {', '.join(NPZ_ACTIVATIONS)})")
    return table[name]()


def _npy_bytes(array: np.ndarray) -> bytes:
    buf = io.BytesIO()
    np.lib.format.write_array(buf, np.ascontiguousarray(array), allow_pickle=False)
    return buf.getvalue()


def _write_npz(record: dict, arrays: dict[str, np.ndarray]) -> bytes:
    """A zip that ``np.load(..., allow_pickle=False)`` reads: ``policy.json`` plus one ``.npy`` per
    array, with fixed member dates and order, so the same weights give the same bytes."""
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", compression=zipfile.ZIP_DEFLATED) as zf:
        zf.writestr(zipfile.ZipInfo(NPZ_RECORD, date_time=_ZIP_DATE),
                    json.dumps(record, indent=2, sort_keys=True, allow_nan=False) + "\n",
                    compress_type=zipfile.ZIP_DEFLATED)
        for name in sorted(arrays):
            zf.writestr(zipfile.ZipInfo(f"{name}.npy", date_time=_ZIP_DATE), _npy_bytes(arrays[name]),
                        compress_type=zipfile.ZIP_DEFLATED)
    return buf.getvalue()


def _one_line(msg) -> str:
    return " ".join(str(msg).split())


def _npy_header(zf: zipfile.ZipFile, info: zipfile.ZipInfo) -> tuple[tuple[int, ...], np.dtype, int]:
    """(shape, dtype, header length) of a ``.npy`` member from its header alone (nothing else is read);
    the declared array must be a C-order float32/float64 array whose bytes fill the member exactly."""
    name = info.filename
    try:
        with zf.open(info) as fh:
            version = np.lib.format.read_magic(fh)
            if version == (1, 0):
                shape, fortran, dtype = np.lib.format.read_array_header_1_0(fh, max_header_size=10000)
            elif version == (2, 0):
                shape, fortran, dtype = np.lib.format.read_array_header_2_0(fh, max_header_size=10000)
            else:
                raise ValueError(f"unsupported .npy version {version}")
            header = fh.tell() if fh.seekable() else None
    except (ValueError, OSError, EOFError, SyntaxError, TypeError, zipfile.BadZipFile) as exc:
        raise PolicyFileError(f"member {name!r} is not a plain .npy array: {_one_line(exc)}") from None
    if dtype.hasobject or dtype.kind != "f" or dtype.itemsize not in (4, 8):
        raise PolicyFileError(f"array {name!r} has dtype {dtype}; only float32/float64 allowed")
    if fortran:
        raise PolicyFileError(f"array {name!r} is in Fortran order; only C order is allowed")
    if len(shape) > 2 or any((not isinstance(n, int)) or n < 0 or n > NPZ_MAX_PARAMETERS for n in shape):
        raise PolicyFileError(f"array {name!r} declares shape {shape}: at most 2 dimensions of at most "
                              f"{NPZ_MAX_PARAMETERS} each")
    size = math.prod(shape) * dtype.itemsize
    if header is None or info.file_size != header + size:
        raise PolicyFileError(f"array {name!r} declares shape {shape} ({size} bytes) but the member holds "
                              f"{info.file_size - (header or 0)} bytes of data")
    return tuple(shape), dtype, header


def read_npz(data: bytes) -> tuple[dict, dict[str, np.ndarray]]:
    """``(record, arrays)`` of a ``ppo-npz`` file, read without unpickling anything.

    Refuses (``PolicyFileError``, one line): a file that is not a zip, members other than ``policy.json``
    and ``*.npy``, more than :data:`NPZ_MAX_MEMBERS` members or :data:`NPZ_MAX_BYTES` uncompressed
    (checked before decompressing), a ``.npy`` header declaring anything but a C-order float32/float64
    array of at most 2 dimensions that fills its member exactly (checked before the data is read), a
    network over the budget (:func:`network_budget`, from the record and the headers, before any
    array is read), arrays that are not finite, and a record of another format.
    """
    try:
        zf = zipfile.ZipFile(io.BytesIO(data))
    except (zipfile.BadZipFile, ValueError, OSError, EOFError) as exc:
        raise PolicyFileError(f"not a {NPZ_FORMAT} policy file (not a zip: {_one_line(exc)})") from None
    with zf:
        infos = zf.infolist()
        if len(infos) > NPZ_MAX_MEMBERS:
            raise PolicyFileError(f"{len(infos)} members, more than the {NPZ_MAX_MEMBERS} allowed")
        total = sum(i.file_size for i in infos)
        if total > NPZ_MAX_BYTES:
            raise PolicyFileError(f"{total} bytes uncompressed, more than the {NPZ_MAX_BYTES} allowed")
        names = [i.filename for i in infos]
        if len(set(names)) != len(names):
            raise PolicyFileError("a member name appears twice")
        if NPZ_RECORD not in names:
            raise PolicyFileError(f"no {NPZ_RECORD} inside: not a {NPZ_FORMAT} policy file")
        headers = {}
        for info in infos:
            name = info.filename
            if name == NPZ_RECORD:
                if info.file_size > NPZ_MAX_RECORD_BYTES:
                    raise PolicyFileError(f"{NPZ_RECORD} is {info.file_size} bytes, more than {NPZ_MAX_RECORD_BYTES}")
                continue
            if not name.endswith(".npy") or "/" in name or name.startswith("."):
                raise PolicyFileError(f"unexpected member {name!r} (only {NPZ_RECORD} and <name>.npy)")
            headers[name] = (info, *_npy_header(zf, info))
        try:
            raw = zf.read(NPZ_RECORD)
            if len(raw) > NPZ_MAX_RECORD_BYTES:
                raise ValueError("larger than declared")
            record = json.loads(raw.decode("utf-8"), parse_constant=lambda c: (_ for _ in ()).throw(ValueError(c)))
        except (UnicodeDecodeError, ValueError, RecursionError, zipfile.BadZipFile, OSError) as exc:
            raise PolicyFileError(f"{NPZ_RECORD} is not valid JSON: {_one_line(exc)}") from None
        if not isinstance(record, dict) or record.get("format") != NPZ_FORMAT:
            raise PolicyFileError(f"{NPZ_RECORD} is not a {NPZ_FORMAT} record")
        if record.get("format_version") != NPZ_FORMAT_VERSION:
            raise PolicyFileError(f"format_version must be {NPZ_FORMAT_VERSION}, got {record.get('format_version')!r}")
        network_budget(record, {n[:-4]: h[1] for n, h in headers.items()})
        arrays: dict[str, np.ndarray] = {}
        for name, (info, shape, dtype, header) in headers.items():
            try:
                with zf.open(info) as fh:
                    fh.read(header)
                    buf = fh.read(info.file_size - header + 1)
            except (zipfile.BadZipFile, OSError, EOFError, ValueError) as exc:
                raise PolicyFileError(f"member {name!r} cannot be read: {_one_line(exc)}") from None
            if len(buf) != info.file_size - header:
                raise PolicyFileError(f"member {name!r} is not the size its header declares")
            array = np.frombuffer(buf, dtype=dtype).reshape(shape)
            if not np.all(np.isfinite(array)):
                raise PolicyFileError(f"array {name!r} holds NaN or inf")
            arrays[name[:-4]] = array
    return record, arrays


def network_budget(record: dict, shapes: dict[str, tuple[int, ...]]) -> dict[str, int]:
    """Parameters, layers, array references and FLOPs per action of the network ``record`` builds from
    arrays of ``shapes`` (nothing allocated); raises :class:`PolicyFileError` when it is malformed or
    over :data:`NPZ_MAX_PARAMETERS`, :data:`NPZ_MAX_LAYERS`, :data:`NPZ_MAX_WIDTH`,
    :data:`NPZ_MAX_FLOPS`, or when an array is referenced more than once (each layer owns its arrays)."""
    net = record.get("network")
    layers = net.get("layers") if isinstance(net, dict) else None
    if not isinstance(layers, list) or not layers:
        raise PolicyFileError("$.network.layers must be a non-empty list")
    if len(layers) > NPZ_MAX_LAYERS:
        raise PolicyFileError(f"$.network.layers has {len(layers)} layers, more than the {NPZ_MAX_LAYERS} allowed")
    refs: list[str] = []
    params = flops = 0
    lstm = net.get("lstm")
    if lstm is not None:  # RecurrentPPO's actor LSTM (one layer) before the layers
        if not isinstance(lstm, dict):
            raise PolicyFileError("$.network.lstm must be an object")
        for key in NPZ_LSTM_ARRAYS:
            ref = lstm.get(key)
            if not isinstance(ref, str) or ref not in shapes:
                raise PolicyFileError(f"$.network.lstm.{key}: array {ref!r} is missing")
            refs.append(ref)
        w_ih, w_hh = shapes[lstm["weight_ih"]], shapes[lstm["weight_hh"]]
        if len(w_ih) != 2 or len(w_hh) != 2 or max(*w_ih, *w_hh) > 4 * NPZ_MAX_WIDTH:
            raise PolicyFileError(f"$.network.lstm: weights {w_ih} / {w_hh} must be 2-D with at most "
                                  f"{NPZ_MAX_WIDTH} hidden units")
        for key in NPZ_LSTM_ARRAYS:
            params += math.prod(shapes[lstm[key]])
        flops += 2 * (math.prod(w_ih) + math.prod(w_hh)) + 10 * w_hh[0]  # gates: mat-vecs + elementwise
    for i, layer in enumerate(layers):
        if not isinstance(layer, dict):
            raise PolicyFileError(f"$.network.layers[{i}] must be an object")
        for key in ("weight", "bias"):
            ref = layer.get(key)
            if not isinstance(ref, str) or ref not in shapes:
                raise PolicyFileError(f"$.network.layers[{i}].{key}: array {ref!r} is missing")
            refs.append(ref)
        w, b = shapes[layer["weight"]], shapes[layer["bias"]]
        if len(w) != 2 or max(w) > NPZ_MAX_WIDTH:
            raise PolicyFileError(f"$.network.layers[{i}]: weight {w} must be 2-D with at most {NPZ_MAX_WIDTH} "
                                  f"inputs and outputs")
        params += math.prod(w) + math.prod(b)
        flops += 2 * math.prod(w) + math.prod(b)
    repeated = sorted({r for r in refs if refs.count(r) > 1})
    if repeated:
        raise PolicyFileError(f"arrays {repeated} are referenced more than once: each layer owns its arrays")
    if params > NPZ_MAX_PARAMETERS:
        raise PolicyFileError(f"the network has {params} parameters, more than the {NPZ_MAX_PARAMETERS} allowed")
    if flops > NPZ_MAX_FLOPS:
        raise PolicyFileError(f"the network needs {flops} FLOPs per action, more than the {NPZ_MAX_FLOPS} allowed")
    return {"parameters": params, "layers": len(layers), "references": len(refs), "flops": flops}


def _check_meta(meta: dict, obs_dim: int) -> None:
    """Every meta value the agent uses has its type and range (:data:`NPZ_META_NUMBERS`...)."""
    for key, (kind, low, high) in NPZ_META_NUMBERS.items():
        if key not in meta:
            continue
        v = meta[key]
        ok = isinstance(v, (int, float)) and not isinstance(v, bool) and (kind is float or isinstance(v, int))
        ok = ok and math.isfinite(v) and (low is None or v >= low) and (high is None or v <= high)
        if not ok:
            bound = f"in [{low}, {high if high is not None else 'inf'}]"
            raise PolicyFileError(f"$.meta.{key} must be a finite {kind.__name__} {bound}, got {v!r}")
    for key in NPZ_META_STRINGS:
        if key in meta and not (isinstance(meta[key], str) and 0 < len(meta[key]) <= 100):
            raise PolicyFileError(f"$.meta.{key} must be a string of 1-100 characters, got {meta[key]!r}")
    for key in NPZ_META_BOOLS:
        if key in meta and not isinstance(meta[key], bool):
            raise PolicyFileError(f"$.meta.{key} must be true or false, got {meta[key]!r}")
    if "obs_var" in meta and isinstance(meta["obs_var"], list) and any(
        isinstance(x, (int, float)) and x < 0 for x in meta["obs_var"]
    ):
        raise PolicyFileError("$.meta.obs_var must hold variances >= 0")


def _check_record(record: dict, arrays: dict[str, np.ndarray]) -> None:
    """Every field the loader uses is present and consistent with the arrays (shapes chain)."""
    def need(obj, key, kind, where):
        value = obj.get(key) if isinstance(obj, dict) else None
        if not isinstance(value, kind) or (isinstance(value, bool) and kind is not bool):
            raise PolicyFileError(f"{where}.{key} must be {getattr(kind, '__name__', kind)}, got {value!r}")
        return value

    allowed = {"format", "format_version", "network", "meta", "source"}
    extra = sorted(set(record) - allowed)
    if extra:
        raise PolicyFileError(f"unknown keys {extra} in {NPZ_RECORD} (allowed: {sorted(allowed)})")
    net = need(record, "network", dict, "$")
    meta = need(record, "meta", dict, "$")
    recurrent = net.get("lstm") is not None
    squash = net.get("squash")
    if squash not in NPZ_SQUASH:
        raise PolicyFileError(f"$.network.squash must be one of {list(NPZ_SQUASH)}, got {squash!r}")
    if squash is not None and recurrent:
        raise PolicyFileError("$.network.squash (SAC) and $.network.lstm (RecurrentPPO) exclude each other")
    algo = "SAC" if squash is not None else "RecurrentPPO" if recurrent else "PPO"
    if need(meta, "algo", str, "$.meta") != algo:
        what = ("with $.network.squash" if squash is not None else
                f"{'with' if recurrent else 'without'} $.network.lstm")
        raise PolicyFileError(f"$.meta.algo must be {algo!r} for a network {what}, got {meta['algo']!r}")
    network_budget(record, {k: v.shape for k, v in arrays.items()})
    obs_dim = need(net, "obs_dim", int, "$.network")
    action_dim = need(net, "action_dim", int, "$.network")
    if not 1 <= obs_dim <= NPZ_MAX_WIDTH or not 1 <= action_dim <= NPZ_MAX_WIDTH:
        raise PolicyFileError(f"$.network.obs_dim / action_dim must be in [1, {NPZ_MAX_WIDTH}]")
    _check_meta(meta, obs_dim)
    layers = need(net, "layers", list, "$.network")
    if not layers:
        raise PolicyFileError("$.network.layers is empty")
    width = obs_dim
    if recurrent:
        lstm = net["lstm"]
        hidden = need(lstm, "hidden_size", int, "$.network.lstm")
        if not 1 <= hidden <= NPZ_MAX_WIDTH:
            raise PolicyFileError(f"$.network.lstm.hidden_size must be in [1, {NPZ_MAX_WIDTH}], got {hidden}")
        want = {"weight_ih": (4 * hidden, obs_dim), "weight_hh": (4 * hidden, hidden), "bias_ih": (4 * hidden,),
                "bias_hh": (4 * hidden,)}
        for key, shape in want.items():
            got = arrays[lstm[key]].shape
            if got != shape:
                raise PolicyFileError(f"$.network.lstm.{key}: array {lstm[key]!r} has shape {got}, an LSTM of "
                                      f"{hidden} units on {obs_dim} inputs needs {shape}")
        width = hidden
    for i, layer in enumerate(layers):
        where = f"$.network.layers[{i}]"
        w = arrays.get(need(layer, "weight", str, where))
        b = arrays.get(need(layer, "bias", str, where))
        if w is None or b is None:
            raise PolicyFileError(f"{where}: array {layer['weight']!r} or {layer['bias']!r} is missing")
        if w.ndim != 2 or w.shape[1] != width or b.shape != (w.shape[0],):
            raise PolicyFileError(f"{where}: weight {w.shape} / bias {b.shape} do not follow a {width}-wide input")
        act = layer.get("activation")
        if act is not None:
            _activation_module(act)
        if i == len(layers) - 1 and act is not None:
            raise PolicyFileError(f"{where}: the action layer has no activation, got {act!r}")
        width = w.shape[0]
    if width != action_dim:
        raise PolicyFileError(f"the last layer gives {width} actions, $.network.action_dim says {action_dim}")
    for key in ("action_low", "action_high"):
        bound = need(net, key, list, "$.network")
        if len(bound) != action_dim or not all(isinstance(x, (int, float)) and not isinstance(x, bool)
                                               and math.isfinite(x) for x in bound):
            raise PolicyFileError(f"$.network.{key} must be {action_dim} finite numbers")
    if "obs_mean" in meta:
        for key in ("obs_mean", "obs_var"):
            v = meta.get(key)
            if not isinstance(v, list) or not all(isinstance(x, (int, float)) and not isinstance(x, bool)
                                                  and math.isfinite(x) for x in v):
                raise PolicyFileError(f"$.meta.{key} must be a list of finite numbers")
        if len(meta["obs_mean"]) != obs_dim or len(meta["obs_var"]) != obs_dim:
            raise PolicyFileError(f"$.meta.obs_mean/obs_var must have {obs_dim} entries (the network's input)")


class NpzActor:
    """The deterministic actor of a ``ppo-npz`` file: a ``torch.nn.Sequential`` built from the JSON
    record, with the arrays copied in; ``__call__(obs) -> action`` as SB3's ``predict(deterministic=True)``
    computes it for a flat Box observation (batch of one, float32, action clipped to the action space).
    With ``network.lstm`` (RecurrentPPO) an ``nn.LSTM`` comes first and its state is carried from call to
    call (:meth:`reset` or ``episode_start=True`` starts it from zeros)."""

    def __init__(self, record: dict, arrays: dict[str, np.ndarray]):
        import torch
        import torch.nn as nn

        _check_record(record, arrays)
        net = record["network"]
        self.lstm = None
        self.state = None  # (h, c) of the LSTM, carried across steps; None: zeros at the next step
        if net.get("lstm") is not None:
            spec = net["lstm"]
            self.lstm = nn.LSTM(int(net["obs_dim"]), int(spec["hidden_size"]), num_layers=1)
            with torch.no_grad():
                for key in NPZ_LSTM_ARRAYS:
                    getattr(self.lstm, f"{key}_l0").copy_(torch.from_numpy(np.array(arrays[spec[key]], dtype=np.float32)))
            self.lstm.eval()
            for param in self.lstm.parameters():
                param.requires_grad_(False)
            self.hidden_size = int(spec["hidden_size"])
        modules = []
        for layer in net["layers"]:
            w, b = arrays[layer["weight"]], arrays[layer["bias"]]
            linear = nn.Linear(w.shape[1], w.shape[0], bias=True)
            with torch.no_grad():
                linear.weight.copy_(torch.from_numpy(np.array(w, dtype=np.float32)))
                linear.bias.copy_(torch.from_numpy(np.array(b, dtype=np.float32)))
            modules.append(linear)
            if layer.get("activation") is not None:
                modules.append(_activation_module(layer["activation"]))
        self.net = nn.Sequential(*modules).eval()
        for param in self.net.parameters():
            param.requires_grad_(False)
        self.obs_dim = int(net["obs_dim"])
        self.squash = net.get("squash")
        self.low = np.asarray(net["action_low"], dtype=np.float32)
        self.high = np.asarray(net["action_high"], dtype=np.float32)
        self._torch = torch

    @property
    def recurrent(self) -> bool:
        return self.lstm is not None

    def reset(self) -> None:
        """Forget the LSTM state (a new episode); nothing to do for an MLP actor."""
        self.state = None

    def __call__(self, obs: np.ndarray, episode_start: bool = False) -> np.ndarray:
        """The deterministic action; a recurrent actor carries its LSTM state to the next call and starts
        from zeros at ``episode_start`` (as sb3-contrib's ``RecurrentPPO.predict``)."""
        torch = self._torch
        x = np.asarray(obs, dtype=np.float32).reshape(1, self.obs_dim)
        with torch.no_grad():
            h = torch.as_tensor(x)
            if self.lstm is not None:
                if episode_start or self.state is None:
                    zeros = torch.zeros((1, 1, self.hidden_size), dtype=torch.float32)
                    self.state = (zeros, zeros.clone())
                out, self.state = self.lstm(h.reshape(1, 1, self.obs_dim), self.state)
                h = out.reshape(1, self.hidden_size)
            out = self.net(h)
            if self.squash == "tanh":  # SB3 SAC: th.tanh of the mean, then unscale_action (numpy, float32)
                a = torch.tanh(out).numpy().reshape(-1, self.low.shape[0])
                return (self.low + (0.5 * (a + 1.0) * (self.high - self.low)))[0]
            out = out.numpy()
        return np.clip(out.reshape(-1, self.low.shape[0]), self.low, self.high)[0]


def _linear_layers(hidden: list, head, what: str) -> tuple[dict, list]:
    """The float32 arrays and layer records of an SB3 actor: its hidden ``Linear``/activation modules in order,
    then the ``head`` Linear (named ``action``; the hidden ones ``pi.<k>``)."""
    arrays, layers = {}, []
    pending = None
    for module in hidden + [head]:
        if type(module).__name__ == "Linear":
            name = "action" if module is head else f"pi.{len(layers)}"
            arrays[f"{name}.weight"] = module.weight.detach().cpu().numpy().astype(np.float32)
            arrays[f"{name}.bias"] = module.bias.detach().cpu().numpy().astype(np.float32)
            layers.append({"weight": f"{name}.weight", "bias": f"{name}.bias", "activation": None})
            pending = layers[-1]
        else:
            if pending is None or pending["activation"] is not None:
                raise ValueError(f"unexpected module {module!r} in the {what}")
            pending["activation"] = _activation_name(module)
    return arrays, layers


def npz_from_model(model, meta: dict) -> bytes:
    """The ``ppo-npz`` bytes of a loaded SB3 ``PPO`` model (MlpPolicy on a flat Box observation)."""
    from gymnasium import spaces
    from stable_baselines3.common.distributions import DiagGaussianDistribution
    from stable_baselines3.common.torch_layers import FlattenExtractor

    policy = model.policy
    recurrent = type(model).__name__ == "RecurrentPPO"
    if meta.get("algo") != type(model).__name__ or type(model).__name__ not in ("PPO", "RecurrentPPO", "SAC"):
        raise ValueError(f"only PPO (MlpPolicy), RecurrentPPO (MlpLstmPolicy) and SAC (MlpPolicy) policies have a "
                         f"pickle-free form; this is a {type(model).__name__} whose meta says {meta.get('algo')!r}")
    if type(model).__name__ == "SAC":
        return _sac_npz(model, meta)
    if recurrent and policy.lstm_actor.num_layers != 1:
        raise ValueError(f"the pickle-free form holds a one-layer LSTM; this actor has {policy.lstm_actor.num_layers}")
    obs_space, act_space = model.observation_space, model.action_space
    if not isinstance(obs_space, spaces.Box) or len(obs_space.shape) != 1:
        raise ValueError(f"needs a flat Box observation space, got {obs_space}")
    if not isinstance(act_space, spaces.Box) or len(act_space.shape) != 1:
        raise ValueError(f"needs a flat Box action space, got {act_space}")
    if policy.squash_output or policy.use_sde or not isinstance(policy.action_dist, DiagGaussianDistribution):
        raise ValueError("needs a diagonal Gaussian policy without squashing or gSDE (SB3 PPO's default)")
    if not isinstance(policy.features_extractor, FlattenExtractor) or (
        not policy.share_features_extractor and not isinstance(policy.pi_features_extractor, FlattenExtractor)
    ):
        raise ValueError("needs SB3's FlattenExtractor (MlpPolicy)")
    arrays, layers = _linear_layers(list(policy.mlp_extractor.policy_net), policy.action_net, "policy network")
    keep = {k: v for k, v in meta.items() if not str(k).startswith("_")}
    import stable_baselines3

    network = {
        "kind": "mlp",
        "description": "deterministic SB3 PPO actor: x = clip((obs - obs_mean) / sqrt(obs_var + epsilon), "
                       "+-clip_obs) as float32 (after the belief features when meta.belief), then "
                       "Linear/activation layers in order, then the action clipped to [action_low, action_high]",
        "obs_dim": int(obs_space.shape[0]),
        "action_dim": int(act_space.shape[0]),
        "layers": layers,
        "action_low": [float(x) for x in act_space.low],
        "action_high": [float(x) for x in act_space.high],
    }
    source = {"converted_from": "stable-baselines3 PPO", "stable_baselines3": stable_baselines3.__version__}
    if recurrent:
        import sb3_contrib

        lstm = policy.lstm_actor
        for key in NPZ_LSTM_ARRAYS:
            arrays[f"lstm.{key}"] = getattr(lstm, f"{key}_l0").detach().cpu().numpy().astype(np.float32)
        network["kind"] = "lstm_mlp"
        network["lstm"] = {"hidden_size": int(lstm.hidden_size), **{key: f"lstm.{key}" for key in NPZ_LSTM_ARRAYS}}
        network["description"] = (
            "deterministic sb3-contrib RecurrentPPO actor: x normalised as for PPO, then a one-layer LSTM "
            "(torch.nn.LSTM, gates i,f,g,o; state (h, c) zero at an episode's first step and carried across "
            "its steps), then Linear/activation layers in order on h, then the action clipped to "
            "[action_low, action_high]")
        source = {"converted_from": "sb3-contrib RecurrentPPO", "stable_baselines3": stable_baselines3.__version__,
                  "sb3_contrib": sb3_contrib.__version__}
    record = {
        "format": NPZ_FORMAT,
        "format_version": NPZ_FORMAT_VERSION,
        "network": network,
        "meta": keep,
        "source": source,
    }
    return _write_npz(record, arrays)


def _sac_npz(model, meta: dict) -> bytes:
    """The ``ppo-npz`` bytes of a loaded SB3 ``SAC`` model (MlpPolicy on a flat Box observation): the actor's
    ``latent_pi`` layers and ``mu``, with ``network.squash = "tanh"`` (the deterministic action is
    ``low + 0.5 (tanh(mu(x)) + 1) (high - low)``, as ``SAC.predict(obs, deterministic=True)``)."""
    from gymnasium import spaces
    from stable_baselines3.common.torch_layers import FlattenExtractor

    actor = model.policy.actor
    obs_space, act_space = model.observation_space, model.action_space
    if not isinstance(obs_space, spaces.Box) or len(obs_space.shape) != 1:
        raise ValueError(f"needs a flat Box observation space, got {obs_space}")
    if not isinstance(act_space, spaces.Box) or len(act_space.shape) != 1:
        raise ValueError(f"needs a flat Box action space, got {act_space}")
    if actor.use_sde or not isinstance(actor.features_extractor, FlattenExtractor):
        raise ValueError("needs SB3 SAC's MlpPolicy actor (FlattenExtractor, no gSDE)")
    arrays, layers = _linear_layers(list(actor.latent_pi), actor.mu, "actor network")
    import stable_baselines3

    network = {
        "kind": "mlp",
        "squash": "tanh",
        "description": "deterministic SB3 SAC actor: x = clip((obs - obs_mean) / sqrt(obs_var + epsilon), "
                       "+-clip_obs) as float32, then Linear/activation layers in order (latent_pi, then mu), "
                       "then a = tanh(.), then the action action_low + 0.5 (a + 1) (action_high - action_low) "
                       "in float32 (SB3's unscale_action; no clipping)",
        "obs_dim": int(obs_space.shape[0]),
        "action_dim": int(act_space.shape[0]),
        "layers": layers,
        "action_low": [float(x) for x in act_space.low],
        "action_high": [float(x) for x in act_space.high],
    }
    record = {
        "format": NPZ_FORMAT,
        "format_version": NPZ_FORMAT_VERSION,
        "network": network,
        "meta": {k: v for k, v in meta.items() if not str(k).startswith("_")},
        "source": {"converted_from": "stable-baselines3 SAC", "stable_baselines3": stable_baselines3.__version__},
    }
    return _write_npz(record, arrays)


def prove_npz_equals_model(data: bytes, model, n: int = NPZ_PROOF_OBSERVATIONS, seed: int = 0) -> int:
    """Raise ValueError unless the actor rebuilt from ``data`` gives ``model.predict(obs, deterministic=True)``
    bit for bit on ``n`` observations (normal draws scaled to cover the clipped normalised range, plus
    the corners +-clip); returns ``n``. A recurrent actor plays them as one stream, carrying its LSTM
    state as ``RecurrentPPO.predict`` does, with a new episode every :data:`NPZ_PROOF_EPISODE` steps."""
    record, arrays = read_npz(data)
    actor = NpzActor(record, arrays)
    clip = float(record["meta"].get("clip_obs", 10.0))
    rng = np.random.default_rng(seed)
    obs = (rng.standard_normal((n, actor.obs_dim)) * (clip / 3.0)).astype(np.float32)
    obs[0], obs[1 % n] = clip, -clip
    state = None
    for i in range(n):
        if actor.recurrent:  # one stream of observations, a new episode every NPZ_PROOF_EPISODE steps
            start = i % NPZ_PROOF_EPISODE == 0
            expected, state = model.predict(obs[i], state=state, episode_start=np.array([start]), deterministic=True)
            got = actor(obs[i], episode_start=start)
        else:
            expected, _ = model.predict(obs[i], deterministic=True)
            got = actor(obs[i])
        if not np.array_equal(np.asarray(expected, dtype=np.float32), got):
            raise ValueError(f"the pickle-free actor differs from the SB3 model on observation {i}: "
                             f"{got.tolist()} vs {np.asarray(expected).tolist()}")
    return n


def pack_npz(path: str | Path) -> bytes:
    """Convert a trained PPO run (folder, ``model.zip`` with its meta, or a packed zip) into the
    pickle-free ``ppo-npz`` bytes, after proving equal actions (:func:`prove_npz_equals_model`).

    Loading the SB3 zip unpickles it: do this only with your own (trusted) model. A ``.npz`` given
    here is returned as it is, after it is read and checked.
    """
    p = Path(path)
    if p.is_file() and p.suffix == ".npz":
        data = p.read_bytes()
        record, arrays = read_npz(data)
        _check_record(record, arrays)
        return data
    model_path, meta_path = resolve(path)
    data = model_path.read_bytes()
    meta = json.loads(meta_path.read_text()) if meta_path is not None else _packed_meta(data)
    if meta is None:
        raise ValueError(f"{model_path} has no {META_NAME}")
    model = _algo_class(meta["algo"]).load(io.BytesIO(data), device="cpu")
    out = npz_from_model(model, meta)
    prove_npz_equals_model(out, model)
    return out


class PPOAgent:
    """Deterministic actions of a trained policy for the flat EyeCatch observation."""

    def __init__(self, path: str | Path, env_id: str | None = None):
        p = Path(path)
        if p.is_file() and p.suffix == ".npz":
            agent = type(self).from_npz(p.read_bytes(), env_id)
            self.__dict__.update(agent.__dict__)
            return
        model_path, meta_path = resolve(path)
        data = model_path.read_bytes()
        meta = json.loads(meta_path.read_text()) if meta_path is not None else _packed_meta(data)
        self._setup(data, meta, env_id)

    @classmethod
    def from_npz(cls, data: bytes, env_id: str | None = None) -> PPOAgent:
        """The agent of a pickle-free ``ppo-npz`` file (:func:`pack_npz`); nothing is unpickled. Every
        failure is a :class:`PolicyFileError` with a one-line message."""
        try:
            record, arrays = read_npz(data)
            agent = cls.__new__(cls)
            agent._setup(None, record["meta"], env_id, actor=NpzActor(record, arrays))
        except PolicyFileError as exc:
            raise PolicyFileError(_one_line(exc)) from None
        except (ValueError, TypeError, KeyError, IndexError, AttributeError, RuntimeError, MemoryError,
                OverflowError, RecursionError) as exc:
            raise PolicyFileError(f"not a loadable {NPZ_FORMAT} policy: {type(exc).__name__}: {_one_line(exc)}") from None
        return agent

    @classmethod
    def from_bytes(cls, data: bytes, env_id: str | None = None) -> PPOAgent:
        """The agent of a packed policy file (:func:`pack_policy`)."""
        meta = _packed_meta(data)
        if meta is None:
            raise ValueError(f"not a packed PPO policy: a zip holding {META_NAME} (see pack_policy)")
        agent = cls.__new__(cls)
        agent._setup(data, meta, env_id)
        return agent

    def _setup(self, data: bytes | None, meta: dict, env_id: str | None, actor: NpzActor | None = None) -> None:
        self.meta = meta
        # Evaluating on another env id than the training one is allowed (e.g. a policy trained on
        # EyeCatch-v0 on the ladder); the belief features then follow the env it runs in.
        self.env_id = env_id or self.meta["env_id"]
        self.actor = actor
        self.model = None if actor is not None else _algo_class(self.meta["algo"]).load(io.BytesIO(data), device="cpu")
        self.features = None
        if self.meta.get("belief"):
            from visuomotor_gym.baselines.ppo.belief import BeliefFeatures

            self.features = BeliefFeatures(self.env_id, self.meta.get("hand_action", "absolute"),
                                           float(self.meta.get("intercept_residual_m", 0.15)),
                                           self.meta.get("gaze_action", "free"),
                                           float(self.meta.get("gaze_residual_deg", 3.0)))
        self.mean = np.asarray(self.meta["obs_mean"]) if "obs_mean" in self.meta else None
        self.std = np.sqrt(np.asarray(self.meta["obs_var"]) + self.meta.get("epsilon", 1e-8)) if self.mean is not None else None
        self.clip = float(self.meta.get("clip_obs", 10.0))
        self.reset()

    def reset(self) -> None:
        self.lstm_state = None
        self.last_policy_action = None
        if self.actor is not None:
            self.actor.reset()
        if self.features is not None:
            self.features.reset()

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        obs = np.asarray(observation, dtype=np.float32)
        start = episode_start is not None and bool(np.asarray(episode_start).reshape(-1)[0])
        if start:
            self.reset()
        if self.features is not None:
            obs = self.features(obs)
        if self.mean is not None:
            obs = np.clip((obs - self.mean) / self.std, -self.clip, self.clip).astype(np.float32)
        if self.actor is not None:
            action = self.actor(obs, episode_start=start)
        elif self.meta["algo"] == "RecurrentPPO":
            action, self.lstm_state = self.model.predict(
                obs, state=self.lstm_state, episode_start=np.array([start]), deterministic=True
            )
        else:
            action, _ = self.model.predict(obs, deterministic=True)
        action = np.clip(np.asarray(action, dtype=np.float32), -1.0, 1.0)  # as SB3 does in training
        self.last_policy_action = action  # the policy's own action (look gate included), for analysis
        if self.features is not None:
            action = self.features.env_action(action)
        return action, state
