"""A material's node graph compiled into a small vectorized program, evaluated over a batch of hits.

A program is a list of instructions over numbered registers. A register holds a float (n,) or a vector / colour
(3, n) as float32 rows, or a constant of the same kind that broadcasts (a 0-d float, a (3, 1) column): constants
stay constants until an output is read, so a graph folds down to what varies per hit. Each instruction names an
operation from :data:`OPERATIONS` (``op(attrs, params, *inputs)`` returning one value or a tuple, one per output
register); ``attrs`` is the batch's :class:`~.attributes.HitAttributes` (positions, normals, texture coordinates,
the material table's images). The outputs map a material field ("base_color", "roughness", "emission", a Mix
weight, ...) to a register and its kind ("float" or "rgb")."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import gabor, ops_ies, ops_layers, ops_math, ops_normals, ops_patterns, ops_sky, ops_spaces, ops_texture

#: every operation an instruction may name
OPERATIONS = {**ops_math.OPERATIONS, **ops_texture.OPERATIONS, **ops_patterns.OPERATIONS,
              **ops_normals.OPERATIONS, **ops_layers.OPERATIONS, **ops_spaces.OPERATIONS, **ops_ies.OPERATIONS,
              **gabor.OPERATIONS, **ops_sky.OPERATIONS}
#: operations that read the hits (never folded into constants)
READS_HITS = ops_texture.READS_HITS | ops_normals.READS_HITS | ops_layers.READS_HITS | ops_spaces.READS_HITS


@dataclass
class Program:
    """``ops``: (operation, output registers, input registers, params) in evaluation order; ``consts``: register ->
    constant value; ``outputs``: field -> (register, "float" | "rgb"); ``reads``: the hit attributes it reads."""

    ops: list = field(default_factory=list)
    consts: dict = field(default_factory=dict)
    outputs: dict = field(default_factory=dict)
    reads: tuple = ()
    vectors: tuple = ()  # the registers that hold vectors or colours (a constant one is kept as a (3, 1) column)

    def _ops_for(self, fields) -> list:
        """The instructions the outputs ``fields`` depend on (all of them for None), in order; cached."""
        key = None if fields is None else tuple(sorted(f for f in fields if f in self.outputs))
        cache = self.__dict__.setdefault("_slices", {})
        if key not in cache:
            if key is None:
                cache[key] = list(self.ops)
            else:
                need = {self.outputs[f][0] for f in key}
                keep = []
                for op in reversed(self.ops):
                    if need.intersection(op[1]):
                        keep.append(op)
                        need.update(op[2])
                cache[key] = keep[::-1]
        return cache[key]

    def run(self, attrs, fields=None) -> dict:
        """The outputs (all, or those named in ``fields``) at the batch's hits: floats (n,), colours (3, n),
        float32. Only the instructions those outputs depend on run."""
        regs = dict(self.consts)
        n = len(attrs)
        vectors = set(self.vectors)
        with np.errstate(all="ignore"):
            for name, outs, ins, params in self._ops_for(fields):
                got = OPERATIONS[name](attrs, params, *[regs[i] for i in ins])
                for o, g in zip(outs, (got,) if len(outs) == 1 else got):
                    regs[o] = g.reshape(3, 1) if o in vectors and np.ndim(g) == 1 else g
        out = {}
        for name, (reg, kind) in self.outputs.items():
            if fields is not None and name not in fields:
                continue
            v = np.asarray(regs[reg], np.float32)
            shape = (3, n) if kind == "rgb" else (n,)
            out[name] = np.ascontiguousarray(np.broadcast_to(v, shape), dtype=np.float32)
        return out

    def has(self, name: str) -> bool:
        return name in self.outputs


def evaluate_constant(name: str, params: dict, *inputs):
    """One operation on constant inputs (graph folding at export), as the renderer would evaluate it."""
    with np.errstate(all="ignore"):
        return OPERATIONS[name](None, params, *inputs)
