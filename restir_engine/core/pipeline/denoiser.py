"""Intel Open Image Denoise (OIDN 2.x) through its C API, on the CPU: the denoiser Cycles uses, from the library the
host application already ships (Blender links it; the caller names where it is).

Images are (h, w, 3) float32 in scene-linear HDR (``hdr`` on); any row order, the same for every input. Guides
follow OIDN's conventions, which are Cycles' Denoising passes: albedo is the first hit's reflectance in [0, 1],
normal the first hit's shading normal in [-1, 1] (any fixed space: ours is camera space, as Cycles'). Cycles'
settings map onto the filter as:

- input passes ``RGB`` | ``RGB_ALBEDO`` | ``RGB_ALBEDO_NORMAL``: which guides are handed over;
- prefilter ``NONE``: the guides are taken as noise-free (``cleanAux``); ``FAST``: guides handed over as noisy
  (OIDN accounts for it); ``ACCURATE``: each guide is denoised by its own filter first, then taken as clean;
- quality ``HIGH`` | ``BALANCED`` | ``FAST``: the filter's quality (the network size).
"""
from __future__ import annotations

import ctypes
import threading
from dataclasses import dataclass

import numpy as np

DEVICE_CPU = 1          # OIDN_DEVICE_TYPE_CPU: host pointers stay valid (a GPU device would need its own buffers)
FORMAT_FLOAT3 = 3       # OIDN_FORMAT_FLOAT3
QUALITY = {"HIGH": 6, "BALANCED": 5, "FAST": 4}   # OIDN_QUALITY_*
INPUT_PASSES = ("RGB", "RGB_ALBEDO", "RGB_ALBEDO_NORMAL")
PREFILTERS = ("NONE", "FAST", "ACCURATE")


class DenoiserUnavailable(RuntimeError):
    """The OIDN library could not be loaded or refused to run (the message says why)."""


@dataclass(frozen=True)
class DenoiseSettings:
    """What to denoise with: Cycles' Denoising settings (Render Properties > Sampling > Denoise)."""

    input_passes: str = "RGB_ALBEDO_NORMAL"
    prefilter: str = "ACCURATE"
    quality: str = "HIGH"
    threads: int = 0   # 0: OIDN's own choice (every core)
    max_memory_mb: int = 0   # scratch memory OIDN may take (it then works in overlapping tiles); 0: its own default


def _declare(lib) -> None:
    vp, cp, sz = ctypes.c_void_p, ctypes.c_char_p, ctypes.c_size_t
    lib.oidnNewDevice.restype, lib.oidnNewDevice.argtypes = vp, [ctypes.c_int]
    lib.oidnCommitDevice.argtypes = [vp]
    lib.oidnReleaseDevice.argtypes = [vp]
    lib.oidnSetDeviceInt.argtypes = [vp, cp, ctypes.c_int]
    lib.oidnGetDeviceInt.restype, lib.oidnGetDeviceInt.argtypes = ctypes.c_int, [vp, cp]
    lib.oidnGetDeviceError.restype = ctypes.c_int
    lib.oidnGetDeviceError.argtypes = [vp, ctypes.POINTER(cp)]
    lib.oidnNewFilter.restype, lib.oidnNewFilter.argtypes = vp, [vp, cp]
    lib.oidnReleaseFilter.argtypes = [vp]
    lib.oidnSetSharedFilterImage.argtypes = [vp, cp, vp, ctypes.c_int, sz, sz, sz, sz, sz]
    lib.oidnSetFilterBool.argtypes = [vp, cp, ctypes.c_bool]
    lib.oidnSetFilterInt.argtypes = [vp, cp, ctypes.c_int]
    lib.oidnCommitFilter.argtypes = [vp]
    lib.oidnExecuteFilter.argtypes = [vp]


class Denoiser:
    """One OIDN CPU device on a loaded library; ``denoise`` is safe to call from several threads (serialized)."""

    def __init__(self, library: str):
        try:
            lib = ctypes.CDLL(library)
            _declare(lib)
        except (OSError, AttributeError) as exc:
            raise DenoiserUnavailable(f"Open Image Denoise could not be loaded from '{library}': {exc}") from exc
        self._lib = lib
        self._lock = threading.Lock()
        self._device = None
        self._threads = None

    @property
    def version(self) -> int:
        """OIDN's version as major·10000 + minor·100 + patch."""
        with self._lock:
            return int(self._lib.oidnGetDeviceInt(self._ensure_device(0), b"version"))

    def _ensure_device(self, threads: int):
        if self._device is not None and self._threads == threads:
            return self._device
        if self._device is not None:
            self._lib.oidnReleaseDevice(self._device)
            self._device = None
        device = self._lib.oidnNewDevice(DEVICE_CPU)
        if not device:
            raise DenoiserUnavailable(f"Open Image Denoise has no CPU device: {self._error(None)}")
        if threads > 0:
            self._lib.oidnSetDeviceInt(device, b"numThreads", int(threads))
        self._lib.oidnCommitDevice(device)
        self._check(device)
        self._device, self._threads = device, threads
        return device

    def _error(self, device) -> str:
        message = ctypes.c_char_p()
        code = self._lib.oidnGetDeviceError(device, ctypes.byref(message))
        return f"error {code}: {(message.value or b'').decode(errors='replace')}" if code else ""

    def _check(self, device) -> None:
        problem = self._error(device)
        if problem:
            raise DenoiserUnavailable(f"Open Image Denoise failed ({problem})")

    def _run(self, device, images: dict, flags: dict, quality: int | None, max_memory_mb: int = 0) -> None:
        """One RT filter over ``images`` {OIDN image name: (h, w, 3) float32 C-contiguous}."""
        lib = self._lib
        filt = lib.oidnNewFilter(device, b"RT")
        if not filt:
            self._check(device)
            raise DenoiserUnavailable("Open Image Denoise has no RT filter")
        try:
            for name, img in images.items():
                h, w = img.shape[:2]
                lib.oidnSetSharedFilterImage(filt, name.encode(), img.ctypes.data, FORMAT_FLOAT3, w, h, 0, 0, 0)
            for name, value in flags.items():
                lib.oidnSetFilterBool(filt, name.encode(), bool(value))
            if quality is not None:
                lib.oidnSetFilterInt(filt, b"quality", quality)
            if max_memory_mb > 0:
                lib.oidnSetFilterInt(filt, b"maxMemoryMB", int(max_memory_mb))
            lib.oidnCommitFilter(filt)
            lib.oidnExecuteFilter(filt)
            self._check(device)
        finally:
            lib.oidnReleaseFilter(filt)

    def denoise(self, color: np.ndarray, albedo: np.ndarray | None = None, normal: np.ndarray | None = None,
                settings: DenoiseSettings = DenoiseSettings()) -> np.ndarray:
        """The denoised (h, w, 3) float32 image of ``color``; the guides used follow ``settings.input_passes``
        (a normal is used only with an albedo, as OIDN requires). Non-finite and negative inputs are read as 0."""
        if settings.input_passes not in INPUT_PASSES or settings.prefilter not in PREFILTERS \
                or settings.quality not in QUALITY:
            raise ValueError(f"unknown denoise settings {settings}")
        color = _clean(color)
        guides = {}
        if albedo is not None and settings.input_passes != "RGB":
            guides["albedo"] = _clipped(_clean(albedo), 0.0)
            if normal is not None and settings.input_passes == "RGB_ALBEDO_NORMAL":
                n = np.ascontiguousarray(np.asarray(normal, np.float32)[..., :3])
                guides["normal"] = _clipped(np.nan_to_num(n, copy=np.shares_memory(n, normal)), -1.0)
        out = np.empty_like(color)
        quality = QUALITY[settings.quality]
        with self._lock:
            device = self._ensure_device(int(settings.threads))
            if settings.prefilter == "ACCURATE":
                for name in guides:
                    clean = np.empty_like(guides[name])
                    self._run(device, {name: guides[name], "output": clean}, {}, quality, settings.max_memory_mb)
                    guides[name] = clean
            flags = {"hdr": True}
            if guides:
                flags["cleanAux"] = settings.prefilter != "FAST"
            self._run(device, {"color": color, **guides, "output": out}, flags, quality, settings.max_memory_mb)
        return out

    def denoise_rgba(self, image: np.ndarray, albedo: np.ndarray | None = None, normal: np.ndarray | None = None,
                     settings: DenoiseSettings = DenoiseSettings()) -> np.ndarray:
        """A float32 copy of the (h, w, 4) ``image`` with its colour denoised (:meth:`denoise`) and its alpha kept
        (the copy made once the denoiser is done, so that it is not held while the denoiser's images are)."""
        rgb = self.denoise(image[..., :3], albedo, normal, settings)
        out = np.empty(image.shape, np.float32)
        out[..., :3] = rgb.reshape(out.shape[:-1] + (3,))
        del rgb
        out[..., 3:] = image[..., 3:]
        return out

    def close(self) -> None:
        with self._lock:
            if self._device is not None:
                self._lib.oidnReleaseDevice(self._device)
                self._device = None


def _clipped(img: np.ndarray, low: float) -> np.ndarray:
    """``img`` (float32, owned by the caller) clipped to [low, 1] in place."""
    return np.clip(img, low, 1.0, out=img)


def _clean(img: np.ndarray) -> np.ndarray:
    """A C-contiguous (h, w, 3) float32 copy with NaN, infinities and negative values set to 0."""
    rgb = np.asarray(img, np.float32)[..., :3]
    out = np.where(np.isfinite(rgb) & (rgb > 0), rgb, np.float32(0))
    return np.ascontiguousarray(out, dtype=np.float32)


_CACHE: dict = {}
_CACHE_LOCK = threading.Lock()


def shared_denoiser(library: str) -> Denoiser:
    """The process's Denoiser for ``library`` (created once: a device costs tens of milliseconds)."""
    with _CACHE_LOCK:
        den = _CACHE.get(library)
        if den is None:
            den = _CACHE[library] = Denoiser(library)
        return den
