"""Load a palpa stress surrogate (``model.safetensors`` + ``model.json``) and predict with numpy.

    >>> from palpa_surrogate import Surrogate
    >>> s = Surrogate("results/gp")              # a directory, or NAME.safetensors / NAME.json
    >>> stress = s.predict(-0.07, 0.18, 30.0)    # x [m], y [m], force [N] -> Pa, one per ROI element
    >>> s.roi_ids, s.roi_centroids, s.kind, s.target, s.metadata

This is the arithmetic of ``palpa predict`` (``surrogate/src/model.rs``, ``mlp/forward.rs``,
``gp/predict.rs``, ``principal.rs``) in the same order of operations, so it prints the same
numbers: the MLP's layers run in float32 and add their rows one input at a time, the GP sums
``k_i coef_i`` row by row in float64 (and its output basis in float32), the tensor target's
largest eigenvalue uses palpa's polynomial of the trigonometric solution. ``exp`` is numpy's
rather than Rust's, so a GP can differ in the last bit; the test allows 1e-6 relative.

Inputs are SI (m, m, N) in the dataset's frame, and for a model trained on a respiratory
campaign (``input_columns`` ending in ``phase``) the respiratory phase, 0 .. 1
(``s.predict(x, y, force, phase)``); outputs are the maximum principal Cauchy stress
of each ROI element in Pa. Only numpy is needed. The file formats:

- ``model.safetensors``: an 8-byte little-endian header length, a JSON header (tensor name ->
  dtype, shape, byte offsets; ``__metadata__``: format, version, kind, target, input_columns,
  input_units, output, output_unit, all strings), then the raw little-endian tensors.
- ``model.json``: kind, input_columns, roi_ids, input_scaling and output_scaling (mean, std per
  column), layer_sizes (MLP), kernel (GP: length_scales, signal_variance), report.target.

Tensors: MLP ``layers.L.weight`` [n_out, n_in] f32 and ``layers.L.bias`` [n_out] f32; GP
``train_inputs`` [n, D], ``coef`` [n, r] or [n, M], ``basis`` [r, M] (optional), ``k_inv``
[n, n]; both ``roi_centroids`` [R, 3] (m). Version-1 GP files name ``coef`` ``alpha``.

Run as a script to predict from the command line (same output columns as ``palpa predict``):

    python python/palpa_surrogate.py MODEL --x -0.07 --y 0.18 --force 30
"""

import json
import os
import struct
import sys

import numpy as np

__all__ = ["Surrogate", "read_safetensors", "max_principal"]

_DTYPES = {"F32": np.float32, "F64": np.float64, "I64": np.int64, "I32": np.int32}

# cos(2/3 acos h) on [0, 1], degree 12, lowest first (surrogate/src/principal.rs).
_C_OF_H = [
    0.5000000000018545,
    0.5773502685612654,
    -0.11111107547193218,
    0.05345755543879388,
    -0.03291229541294255,
    0.022800102183530662,
    -0.01675000054648387,
    0.012328409662911998,
    -0.008408648047377596,
    0.004814109735422088,
    -0.0020619415958669346,
    0.0005671066134395074,
    -7.359112361478683e-05,
]


def read_safetensors(path):
    """Tensors (name -> numpy array) and the header's ``__metadata__`` (dict of str)."""
    with open(path, "rb") as f:
        data = f.read()
    if len(data) < 8:
        raise ValueError(f"{path}: not a safetensors file (shorter than its header length)")
    (n,) = struct.unpack("<Q", data[:8])
    if 8 + n > len(data):
        raise ValueError(f"{path}: not a safetensors file (header of {n} bytes past the end)")
    header = json.loads(data[8:8 + n].decode("utf-8"))
    meta = header.pop("__metadata__", None) or {}
    base = 8 + n
    tensors = {}
    for name, t in header.items():
        dt = _DTYPES.get(t["dtype"])
        if dt is None:
            raise ValueError(f"{path}: tensor {name}: dtype {t['dtype']} not supported")
        a, b = t["data_offsets"]
        arr = np.frombuffer(data[base + a:base + b], dtype=np.dtype(dt).newbyteorder("<"))
        tensors[name] = arr.reshape(t["shape"]).astype(dt)
    return tensors, meta


def model_paths(path):
    """The .safetensors and .json of ``path`` (a directory holds model.*)."""
    if path.endswith(".safetensors"):
        return path, path[: -len(".safetensors")] + ".json"
    if path.endswith(".json"):
        return path[: -len(".json")] + ".safetensors", path
    return os.path.join(path, "model.safetensors"), os.path.join(path, "model.json")


def max_principal(s):
    """Largest eigenvalue of each symmetric tensor, rows [xx, yy, zz, xy, yz, zx] (R x 6)."""
    s = np.asarray(s, dtype=np.float64)
    m = (s[:, 0] + s[:, 1] + s[:, 2]) * (1.0 / 3.0)
    a, b, c = s[:, 0] - m, s[:, 1] - m, s[:, 2] - m
    q = np.abs(a)
    for x in (b, c, s[:, 3], s[:, 4], s[:, 5]):
        q = np.maximum(q, np.abs(x))
    with np.errstate(divide="ignore"):
        iq = np.where(q > 0.0, 1.0 / q, 0.0)
    a, b, c = a * iq, b * iq, c * iq
    xy, yz, zx = s[:, 3] * iq, s[:, 4] * iq, s[:, 5] * iq
    p2 = (0.5 * (a * a + b * b + c * c) + xy * xy + yz * yz + zx * zx) * (1.0 / 3.0)
    det = a * (b * c - yz * yz) - xy * (xy * c - yz * zx) + zx * (xy * yz - b * zx)
    p = np.sqrt(p2)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.where(p2 > 0.0, np.clip(0.5 * det / (p2 * p), -1.0, 1.0), 0.0)
    h = np.sqrt(0.5 * (1.0 + r))
    cth = np.full_like(h, _C_OF_H[12])
    for k in range(11, -1, -1):
        cth = cth * h + _C_OF_H[k]
    return m + 2.0 * q * p * cth


class Surrogate:
    """A saved palpa surrogate, ready to predict (see the module doc)."""

    def __init__(self, path):
        st, js = model_paths(path)
        for p in (st, js):
            if not os.path.exists(p):
                raise FileNotFoundError(
                    f"{p}: no such file (a model is model.safetensors + model.json, as palpa train --out writes)"
                )
        with open(js) as f:
            self.meta = json.load(f)
        if self.meta.get("format") != "palpa-surrogate":
            raise ValueError(f"{js}: format {self.meta.get('format')!r}, expected 'palpa-surrogate'")
        tensors, self.metadata = read_safetensors(st)
        self.kind = self.meta["kind"]
        self.target = self.meta.get("report", {}).get("target", "principal")
        for key, want in (("kind", self.kind), ("target", self.target)):
            got = self.metadata.get(key)
            if got is not None and got != want:
                raise ValueError(f"{st}: __metadata__ {key} is {got!r} but {js} says {want!r}")
        self.input_columns = self.meta["input_columns"]
        self.roi_ids = np.asarray(self.meta["roi_ids"], dtype=np.int64)
        r = len(self.roi_ids)
        self.roi_centroids = tensors["roi_centroids"].astype(np.float64).reshape(r, 3)
        self.in_mean = np.asarray(self.meta["input_scaling"]["mean"], dtype=np.float64)
        self.in_std = np.asarray(self.meta["input_scaling"]["std"], dtype=np.float64)
        self.out_mean = np.asarray(self.meta["output_scaling"]["mean"], dtype=np.float64)
        self.out_std = np.asarray(self.meta["output_scaling"]["std"], dtype=np.float64)
        m = r * (6 if self.target == "tensor" else 1)
        if len(self.out_mean) != m:
            raise ValueError(f"{js}: {len(self.out_mean)} output scales for {m} outputs")
        if self.kind == "mlp":
            sizes = self.meta["layer_sizes"]
            self.layers = []
            for l in range(len(sizes) - 1):
                w = tensors[f"layers.{l}.weight"].astype(np.float32)  # [n_out, n_in]
                b = tensors[f"layers.{l}.bias"].astype(np.float32)
                if w.shape != (sizes[l + 1], sizes[l]):
                    raise ValueError(f"{st}: layers.{l}.weight has shape {w.shape}")
                # input-major rows, as palpa adds them
                self.layers.append((np.ascontiguousarray(w.T), b))
        elif self.kind == "gp":
            k = self.meta["kernel"]
            self.length_scales = np.asarray(k["length_scales"], dtype=np.float64)
            self.signal_variance = float(k["signal_variance"])
            u = tensors["train_inputs"].astype(np.float64)
            self.scaled_train = u / self.length_scales
            coef = tensors.get("coef", tensors.get("alpha"))
            if coef is None:
                raise ValueError(f"{st}: missing tensor coef")
            self.coef = coef.astype(np.float64)
            basis = tensors.get("basis")
            self.basis = None if basis is None else basis.astype(np.float64).astype(np.float32)
            self.k_inv = tensors["k_inv"].astype(np.float64)
        else:
            raise ValueError(f"{js}: kind {self.kind!r}, expected mlp or gp")

    def takes_phase(self):
        """Whether the model takes the respiratory phase (trained on a respiratory campaign)."""
        return "phase" in self.input_columns

    def raw(self, x, y, force, phase=None):
        """The model's raw outputs (R, or 6R stress components on the tensor target), Pa."""
        if phase is not None and not self.takes_phase():
            raise ValueError("this model takes x, y and force only: no phase")
        if phase is not None and not 0.0 <= phase <= 1.0:
            raise ValueError(f"phase = {phase} is outside 0 (exhalation) .. 1 (inspiration)")
        inputs = np.array([x, y, force, 0.0 if phase is None else phase], dtype=np.float64)
        inputs = inputs[: len(self.input_columns)]
        u = (inputs - self.in_mean) / self.in_std
        if self.kind == "mlp":
            a = u.astype(np.float32)
            last = len(self.layers) - 1
            for li, (w, b) in enumerate(self.layers):
                out = b.copy()
                for i in range(w.shape[0]):
                    if a[i] != 0.0:
                        out += a[i] * w[i]
                if li != last:
                    out = np.maximum(out, np.float32(0.0))
                a = out
            return a.astype(np.float64) * self.out_std + self.out_mean
        u = u / self.length_scales
        d = self.scaled_train - u
        r2 = np.zeros(len(d))
        for j in range(d.shape[1]):
            r2 = r2 + d[:, j] * d[:, j]
        k = self.signal_variance * np.exp(-0.5 * r2)
        z = np.zeros(self.coef.shape[1])
        for i in range(len(k)):
            if k[i] != 0.0:
                z += k[i] * self.coef[i]
        if self.basis is None:
            out = z
        else:
            z32 = z.astype(np.float32)
            out32 = np.zeros(self.basis.shape[1], dtype=np.float32)
            for j in range(len(z32)):
                if z32[j] != 0.0:
                    out32 += z32[j] * self.basis[j]
            out = out32.astype(np.float64)
        return out * self.out_std + self.out_mean

    def predict(self, x, y, force, phase=None):
        """ROI maximum principal stress [Pa] for a finger at x, y [m] pressing with force [N],
        at the respiratory phase (0 exhalation .. 1 inspiration; 0 when not given) for a model
        that takes one."""
        raw = self.raw(x, y, force, phase)
        if self.target == "tensor":
            return max_principal(raw.reshape(-1, 6))
        return raw


def main(argv):
    import argparse

    ap = argparse.ArgumentParser(description="Predict the ROI stress with a palpa surrogate.")
    ap.add_argument("model")
    ap.add_argument("--x", type=float, required=True, help="finger x [m]")
    ap.add_argument("--y", type=float, required=True, help="finger y [m]")
    ap.add_argument("--force", type=float, required=True, help="force [N]")
    ap.add_argument("--phase", type=float, help="respiratory phase, 0 .. 1 (a model that takes one)")
    a = ap.parse_args(argv)
    s = Surrogate(a.model)
    stress = s.predict(a.x, a.y, a.force, a.phase)
    print(f"{s.kind} model {a.model} on the {s.target} target: {len(stress)} ROI elements")
    print("element_id stress_Pa")
    for i, v in zip(s.roi_ids, stress):
        print(f"{i} {v:.6e}")


if __name__ == "__main__":
    main(sys.argv[1:])
