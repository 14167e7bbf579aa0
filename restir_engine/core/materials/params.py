"""BSDF parameters of hits and materials: :class:`SurfaceParams`, named float32 rows of one block (the Principled
model's lobe weights folded into their Fresnel terms; see the class), gathered per hit from the material table on
first use; and the average-Fresnel terms of the multiscatter compensation. Colours are scene-linear RGB."""
from __future__ import annotations

import numpy as np

from . import microfacet_tables as tables
from .microfacet_tables import ALPHA_MIN

_F82 = 6.0 / 7.0  # 1 - cos 82°-ish: the F82 model's reference angle has cos θ = 1/7


def luminance(rgb: np.ndarray) -> np.ndarray:
    """Rec. 709 luminance of scene-linear RGB in the last axis (..., 3)."""
    return np.float32(0.2126) * rgb[..., 0] + np.float32(0.7152) * rgb[..., 1] + np.float32(0.0722) * rgb[..., 2]


def luminance_rows(rgb: np.ndarray) -> np.ndarray:
    """Rec. 709 luminance of scene-linear RGB as (3, ...) rows."""
    return np.float32(0.2126) * rgb[0] + np.float32(0.7152) * rgb[1] + np.float32(0.0722) * rgb[2]


def fss_dielectric(eta: np.ndarray) -> np.ndarray:
    """Cycles' fit of the cosine-weighted average of the exact dielectric Fresnel (η ≥ 1)."""
    return (eta - 1.0) / (4.08567 + 1.00071 * eta)


def multiscatter_fresnel(fss: np.ndarray, e_avg: np.ndarray) -> np.ndarray:
    """Fms = Fss E_avg / (1 - Fss (1 - E_avg)) (Kulla and Conty's multiple-bounce Fresnel, one Fss cancelled)."""
    return fss * e_avg / (1.0 - fss * (1.0 - e_avg))


#: Rows of a SurfaceParams block: RGB triples, then scalars (see :class:`SurfaceParams`).
PARAM_ROWS = {"diffuse": slice(0, 3), "a_m": slice(3, 6), "b_m": slice(6, 9), "d_m": slice(9, 12),
              "fm": slice(12, 15), "a_d": slice(15, 18), "c_d": slice(18, 21), "fd": slice(21, 24),
              "msd": slice(24, 27), "diel_f0": slice(27, 30), "alpha": 30, "eta2m1": 31, "f0r": 32, "p_spec": 33,
              "spec_on": 34, "metal": 35, "diel": 36, "on_a": 37, "on_b": 38, "on_ems": slice(39, 42), "sss": slice(42, 45),
              "sss_albedo": slice(45, 48)}
PARAM_WIDTH = 48
#: The rows that scale with a lobe's weight (Mix/Add components: core/materials/mix.py)
WEIGHT_ROWS = (slice(0, 12), slice(15, 21), slice(42, 45))


class SurfaceParams:
    """Per-hit (or per-material) BSDF parameters as named rows (:data:`PARAM_ROWS`) of one (PARAM_WIDTH, n) float32
    block: a material table, a per-hit block (one ``np.take``), or a table's per-hit view (:meth:`gather`) whose rows
    are gathered when first read. The lobes' weights are folded into their Fresnel terms:
      diffuse (3) base (1 - metallic)
      a_m, b_m, d_m (3) metal: metallic · F0, metallic · (1 - F0) · f90, metallic · b  (F_m = F0 + (f90 - F0) c⁵
                     - b ωo·h c⁶ with c = 1 - ωo·h; f90 = 1 for Principled metals, F0 for the Glossy BSDF)
      fm, fd (3)     multiscatter terms ms · Fms of the metal and the dielectric lobe (ms = 1 for Multiscatter GGX)
      a_d, c_d (3)   dielectric: F_d = mix(f0t, 1, (F - f0)/(1 - f0)) = a_d + c_d · (F - f0), times (1 - metallic)
      msd (3)        ms - fd: the dielectric layer's albedo is (1 - (1 - E) msd) · mix(f0t, 1, S)
      diel_f0 (3)    f0t = f0 · Specular Tint (0 without a dielectric lobe)
      alpha, eta2m1 = η² - 1, f0r = f0 (untinted), p_spec (probability of sampling a specular lobe), spec_on (1
      where a specular lobe exists), metal, diel (1 where that lobe exists)
      on_a, on_b, on_ems (3)  the diffuse lobe's energy-preserving Oren–Nayar (Cycles 4.3+; Lambert: 1/π, 0, 0):
                     f_d = diffuse · layer · (a + b t + Ems (1 - E(cos θo)) (1 - E(cos θi))), see :func:`oren_nayar_E`
      sss (3)        the subsurface share of the diffuse lobe, min(base, 1) (1 - metallic) · Subsurface Weight,
                     layered like the diffuse lobe (core/integrators/subsurface.py walks it at camera hits; elsewhere
                     it is folded back into ``diffuse``: :meth:`fold_subsurface`)
      sss_albedo (3) min(base, 1): the colour the walk's medium is fitted to (not scaled by Mix weights)."""

    __slots__ = ("_block", "lobes", "_table", "_idx", "_rows", "_mu_rows")

    def __init__(self, block: np.ndarray, lobes: frozenset | None = None):
        self._block = block
        self._table = self._idx = self._rows = self._mu_rows = None
        # the optional lobes some entry may have: "metal", "diel", "tint" (a metal's F82 tint), "rough_diffuse"
        # (Oren–Nayar), "coloured_layer" (a dielectric f0t or msd that is not grey). A superset, kept through
        # take/assign, so per-hit blocks skip what no material has without scanning their rows
        self.lobes = lobes if lobes is not None else self._scan()

    def _scan(self) -> frozenset:
        b = self.block
        f0t, msd = b[PARAM_ROWS["diel_f0"]], b[PARAM_ROWS["msd"]]
        # (a pure metal's tinted f0t is weighed by nothing: its dielectric lobe and diffuse weight are 0)
        coloured = ((f0t != f0t[0]) | (msd != msd[0])) & (b[PARAM_ROWS["diel"]] > 0)
        found = (("metal", b[PARAM_ROWS["metal"]]), ("diel", b[PARAM_ROWS["diel"]]), ("tint", b[PARAM_ROWS["d_m"]]),
                 ("rough_diffuse", b[PARAM_ROWS["on_b"]]), ("coloured_layer", coloured))
        return frozenset(name for name, rows in found if rows.any())

    def gather(self, idx: np.ndarray) -> "SurfaceParams":
        """Parameters of entries ``idx`` (an index array into this table), each named row gathered on first use:
        a chunk of hits reads only the rows of the lobes it has (and one channel of a grey row, :meth:`grey`)."""
        out = SurfaceParams.__new__(SurfaceParams)
        out._block = None
        out._table, out._idx, out._rows = self.block, idx, {}
        out.lobes = self.lobes
        out._mu_rows = self.mu_rows() if self.has("diel") and not self.has("coloured_layer") else None
        return out

    def mu_rows(self) -> dict:
        """This table's view terms as functions of μo, per entry (m, N_MU) at the GGX tables' μ nodes, for a grey
        dielectric layer (Specular Tint white): "E" the GGX albedo, "W" the diffuse lobe's layering weight over π
        max(1 - mix(f0t, 1, S)(1 - (1 - E) msd), 0)/π, "A" and "C" the dielectric's spec_a and spec_c
        (a_d, c_d times 1 + fd (1 - E)/E); each as (values, steps to the next node), flat float32 (computed
        once; :func:`lerp_at` reads them at a hit's μo)."""
        if self._mu_rows is None:
            e = tables.albedo_rows(self.alpha).astype(np.float64)
            s = tables.layer_rows(self.alpha, self.f0r).astype(np.float64)
            b = self.block.astype(np.float64)

            def grey(name):
                return b[PARAM_ROWS[name].start][:, None]
            cd = grey("fd") * ((1.0 - e) / e) + 1.0
            la = (grey("diel_f0") * (1.0 - s) + s) * (1.0 - (1.0 - e) * grey("msd"))

            def flat(x):
                x = x.astype(np.float32)
                step = np.zeros_like(x)
                step[:, :-1] = np.diff(x, axis=1)
                return x.ravel(), step.ravel()
            self._mu_rows = {"E": flat(e), "W": flat(np.maximum(1.0 - la, 0.0) / np.pi), "A": flat(cd * grey("a_d")),
                             "C": flat(cd * grey("c_d"))}
        return self._mu_rows

    def view_mu_rows(self) -> dict | None:
        """For a table's per-hit view without a coloured dielectric layer: the table's :meth:`mu_rows` (else None)."""
        return self._mu_rows if self._block is None else None

    @property
    def block(self) -> np.ndarray:
        """All rows (PARAM_WIDTH, n) (gathered now if they were not)."""
        if self._block is None:
            self._block = np.take(self._table, self._idx, axis=1, mode="wrap")
            self._table = self._idx = self._rows = self._mu_rows = None
        return self._block

    def has(self, lobe: str) -> bool:
        """Whether some entry may have ``lobe`` (False: none has it)."""
        return lobe in self.lobes

    def __getattr__(self, name):
        rows = PARAM_ROWS.get(name)
        if rows is None:
            raise AttributeError(name)
        if self._block is not None:
            return self._block[rows]
        got = self._rows.get(name)
        if got is None:  # mode "wrap" skips the bounds check (the indices are in range by construction)
            got = self._rows[name] = np.take(self._table[rows], self._idx, axis=-1, mode="wrap")
        return got

    def grey(self, name: str) -> np.ndarray:
        """The first channel (n,) of RGB row ``name`` (all of it where the row is grey)."""
        rows = PARAM_ROWS[name]
        if self._block is not None:
            return self._block[rows.start]
        got = self._rows.get(name)
        if got is not None:
            return got[0]
        key = name + "/0"
        got = self._rows.get(key)
        if got is None:
            got = self._rows[key] = np.take(self._table[rows.start], self._idx, mode="wrap")
        return got

    def __len__(self) -> int:
        return self._block.shape[1] if self._block is not None else len(self._idx)

    def take(self, idx) -> "SurfaceParams":
        """Parameters of entries ``idx`` (index array or slice)."""
        if self._block is None:  # still a view of the table: compose the indices
            out = SurfaceParams.__new__(SurfaceParams)
            out._block = None
            out._table, out._idx, out._rows, out._mu_rows = self._table, self._idx[idx], {}, self._mu_rows
            out.lobes = self.lobes
            return out
        if isinstance(idx, slice):
            return SurfaceParams(self._block[:, idx], self.lobes)
        # mode "wrap" skips the bounds check: 30-40 % faster (the indices are in range by construction); the
        # result is C-ordered, rows contiguous
        return SurfaceParams(np.take(self._block, idx, axis=1, mode="wrap"), self.lobes)

    def assign(self, idx, other: "SurfaceParams") -> None:
        """self[idx] = other (every row; gathers all rows of both)."""
        self.block[:, idx] = other.block
        self.lobes = self.lobes | other.lobes

    def has_subsurface(self) -> bool:
        """Whether some entry has a subsurface share (its ``sss`` row not zero)."""
        return bool(self.sss.any())

    def fold_subsurface(self, where: np.ndarray | None = None) -> None:
        """Render the subsurface share as part of the diffuse lobe (in place): diffuse += sss, sss = 0; only at the
        entries and channels ``where`` ((3, n) bool) when given."""
        b = self.block
        d, s = b[PARAM_ROWS["diffuse"]], b[PARAM_ROWS["sss"]]
        if where is None:
            d += s
            s[:] = 0.0
        else:
            d[where] += s[where]
            s[where] = 0.0

    def scale(self, factor: np.ndarray) -> None:
        """Scale every lobe by ``factor`` (n,) in place (Fresnel and layering terms are ratios: unchanged)."""
        for rows in WEIGHT_ROWS:
            self.block[rows] *= factor

    def tint(self, colour: np.ndarray) -> None:
        """Multiply every lobe by ``colour`` (3, n) in place (scene-linear RGB per entry); a coloured factor makes
        the dielectric layer coloured (its a_d, c_d rows stop being grey)."""
        for rows in WEIGHT_ROWS:
            block = self.block[rows]
            block.reshape(-1, 3, block.shape[-1])[:] *= colour
        if ((colour != colour[0]) & (self.block[PARAM_ROWS["diel"]] > 0)).any():
            self.lobes = self.lobes | {"coloured_layer"}

    @staticmethod
    def from_material(base, metallic, roughness, f0_d, spec_tint=None, metal_f90=None, multiscatter=None,
                      diffuse_roughness=None, subsurface=None):
        """From base colours (m, 3) (scene-linear RGB, as the material table stores them), metallic, roughness,
        the dielectric f0 (m,) (IOR and Specular IOR Level applied; 0 = no dielectric lobe), and optionally the
        Specular Tint (m, 3) (white), metal_f90 (m,) (1), multiscatter (m,) (1), the diffuse roughness (m,) (0:
        Lambert) and the Subsurface Weight (m,) (0)."""
        m = len(metallic)
        base = np.maximum(np.asarray(base, np.float32), 0).T
        met = np.clip(np.asarray(metallic, np.float32), 0, 1)
        tint = np.ones((3, m), np.float32) if spec_tint is None else np.maximum(np.asarray(spec_tint, np.float32), 0).T
        f90 = np.ones(m, np.float32) if metal_f90 is None else np.asarray(metal_f90, np.float32)
        ms = np.ones(m, np.float32) if multiscatter is None else np.asarray(multiscatter, np.float32)
        f0r = np.clip(np.asarray(f0_d, np.float32), 0, 0.99 ** 2)
        alpha = np.maximum(np.clip(np.asarray(roughness, np.float32), 0, 1) ** 2, ALPHA_MIN)
        e_avg = tables.average_albedo(alpha)
        # metal: F82-tint (b from the tint where f90 = 1), or the Glossy BSDF's constant colour
        metal_f0 = np.minimum(base, 1.0)
        f5 = _F82 ** 5
        tint82 = np.minimum(tint, 1.0)
        metal_b = np.where(f90 > 0, (metal_f0 + (1 - metal_f0) * f5) * (7.0 / (f5 * _F82)) * (1 - tint82), 0.0)
        fss_m = np.where(f90 > 0, metal_f0 + (1 - metal_f0) / 21.0 - metal_b / 126.0, metal_f0)
        # dielectric: f0 tinted, η from the untinted f0
        sq = np.sqrt(f0r)
        eta = (1 + sq) / (1 - sq)
        diel = f0r > 0
        diel_f0 = np.clip(f0r * tint, 0, 1) * diel
        s_ss = np.clip((fss_dielectric(eta) - f0r) / np.maximum(1 - f0r, 1e-6), 0, 1)
        fss_d = diel_f0 + (1 - diel_f0) * s_ss
        diel_w = np.where(diel, 1 - met, 0.0)
        metal = (met > 0) & ((metal_f0.max(axis=0) > 0) | (f90 > 0))
        out = SurfaceParams(np.zeros((PARAM_WIDTH, m), np.float32), frozenset())  # its lobes: scanned once filled
        b = out.block
        sss = np.zeros(m, np.float32) if subsurface is None else np.clip(np.asarray(subsurface, np.float32), 0, 1)
        b[PARAM_ROWS["diffuse"]] = base * ((1 - met) * (1 - sss))
        b[PARAM_ROWS["sss"]] = np.minimum(base, 1.0) * ((1 - met) * sss)
        b[PARAM_ROWS["sss_albedo"]] = np.minimum(base, 1.0)
        b[PARAM_ROWS["a_m"]] = met * metal_f0
        b[PARAM_ROWS["b_m"]] = met * (1 - metal_f0) * f90
        b[PARAM_ROWS["d_m"]] = met * metal_b
        b[PARAM_ROWS["fm"]] = ms * multiscatter_fresnel(fss_m, e_avg)
        b[PARAM_ROWS["a_d"]] = diel_w * diel_f0
        b[PARAM_ROWS["c_d"]] = diel_w * (1 - diel_f0) / np.maximum(1.0 - f0r, 1e-6)
        fd = ms * multiscatter_fresnel(fss_d, e_avg)
        b[PARAM_ROWS["fd"]] = fd
        b[PARAM_ROWS["msd"]] = ms - fd
        b[PARAM_ROWS["diel_f0"]] = diel_f0
        b[PARAM_ROWS["alpha"]] = alpha
        b[PARAM_ROWS["eta2m1"]] = eta * eta - 1
        b[PARAM_ROWS["f0r"]] = f0r
        ws = luminance_rows(metal_f0 + (1 - metal_f0) * (0.05 * f90)) * met + luminance_rows(diel_f0) * diel_w
        wd = luminance_rows(base * (1 - met)) * (1 - f0r)  # (the subsurface share included: folded or walked)
        tot = ws + wd
        p = np.where(tot > 0, ws / np.maximum(tot, 1e-12), 0.0)
        both = (ws > 0) & (wd > 0)
        b[PARAM_ROWS["p_spec"]] = np.where(both, np.clip(p, 0.1, 0.9), p)
        b[PARAM_ROWS["spec_on"]] = metal | (diel_w > 0)
        b[PARAM_ROWS["metal"]] = metal
        b[PARAM_ROWS["diel"]] = diel_w > 0
        sigma = np.zeros(m, np.float32) if diffuse_roughness is None else np.clip(diffuse_roughness, 0, 1)
        sigma = np.where(sigma < 1e-5, 0.0, sigma)
        on_a = 1.0 / (np.pi + sigma * (np.pi / 2 - 2.0 / 3.0))
        on_b = sigma * on_a
        e_avg_on = on_a * np.pi + ((2 * np.pi - 5.6) / 3.0) * on_b
        albedo = np.clip(base, 0, 1)
        b[PARAM_ROWS["on_a"]] = on_a
        b[PARAM_ROWS["on_b"]] = on_b
        b[PARAM_ROWS["on_ems"]] = (albedo * albedo * (e_avg_on / np.maximum(1 - e_avg_on, 1e-12)) / np.pi
                                   / (1 - albedo * (1 - e_avg_on))) * (on_b > 0)
        out.lobes = out._scan()
        return out

    @staticmethod
    def of_table(mats, idx=None, base=None) -> "SurfaceParams":
        """Parameters of materials ``idx`` (all when None) of a scene.MaterialTable, with ``base`` (k, 3) instead
        of their base colours when given (textures)."""
        sel = slice(None) if idx is None else idx
        dr = getattr(mats, "diffuse_roughness", None)
        return SurfaceParams.from_material(mats.base_color[sel] if base is None else base, mats.metallic[sel],
                                           mats.roughness[sel], mats.f0[sel], mats.specular_tint[sel],
                                                   mats.metal_f90[sel], mats.multiscatter[sel],
                                           None if dr is None else dr[sel], subsurface_of(mats, sel))


def subsurface_of(mats, sel) -> np.ndarray | None:
    """The Subsurface Weight (k,) of materials ``sel`` of a scene.MaterialTable (None where it has none)."""
    w = getattr(mats, "subsurface", None)
    return None if w is None else w[sel]
