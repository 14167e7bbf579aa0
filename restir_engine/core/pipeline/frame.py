"""One frame's lifecycle: its trace context (acceleration structures, light table), methods, film and temporal
history, rendering sample passes through the stages the pass's plan names (plan.py lists them in order).

Images are (h, w, c) float32 with row 0 at the *bottom* (Blender's pass order), covering the camera window
(border) only. Temporal reuse runs through the first sample pass of each frame: pass 0 reuses the previous frame's
pass 0 (``prev_history``) and becomes the next frame's (``history``); the other passes of a frame are independent of
each other, so a frame's average is not correlated. A pass may render several samples at once (batches.py).
"""
from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field

import numpy as np

from ..integrators import pathtracer, trace_context
from ..integrators.context_cache import context_for, fingerprint
from ..lights.groups import GroupMap
from ..modes import DirectMethod, Integrator
from ..parallel.pool import quiet_float_errors
from ..parallel.tasks import Progress, Stopped, chunk_size, spans
from ..parallel.team import Solo
from ..profile import NullClock
from ..restir import di, gi
from ..restir.history import TemporalHistory
from ..restir.target import ShadingTerms, width
from ..sampling import finite
from ..scene import Scene
from . import coverage as coverage_mod
from .adaptive import AdaptiveSampling
from . import direct, methods, paths, primary, reuse, shade
from .data_passes import render_data_passes
from .batches import BatchChoice
from .film import Film
from .indirect_choice import IndirectChoice
from .plan import PassPlan
from .runner import PassRunner
from .settings import RenderSettings, validate
from .shadow_catcher import Catchers, film_mode
from .work import frame_reservoirs, hand_back, make_chunks, own, place



class Cancelled(Exception):
    """Raised when ``should_stop`` asked to stop before any sample pass finished."""


@dataclass
class FrameResult:
    """passes: name -> (h, w, c) float32 (bottom row first); samples_done; seconds; cancelled; stats (with
    "stages" when a clock timed the frame); history for the next frame (ReSTIR with temporal reuse)."""

    passes: dict
    samples_done: int
    seconds: float
    cancelled: bool = False
    stats: dict = field(default_factory=dict)
    history: object = None


class FrameRenderer:
    """One frame's acceleration structures and light table, rendering sample passes into its film.

    ``render_frame`` drives it for final renders; the viewport keeps one alive between redraws and swaps the camera
    with :meth:`move_camera` (geometry and lights stay built).
    """

    def __init__(self, scene: Scene, settings: RenderSettings, history=None, clock=None, team=None,
                 film_zeros=None, keep_history: bool = True):
        validate(settings)
        t0 = time.perf_counter()
        self.settings = settings
        # whether the first pass's G-buffer and reservoirs are kept for a next frame or view (a still's are not:
        # its other passes never read them, and they would hold a second set of the frame's target terms)
        self.keeps_history = bool(keep_history)
        self.clock = clock or NullClock()
        # the processes rendering this frame's passes together (parallel/team.py; Solo: this one alone), and the
        # film's accumulators where they are shared (Film's ``zeros``)
        self.team, self.film_zeros = team or Solo(), film_zeros
        bounces = methods.bounces(settings)
        self.ctx, self.context_reused = context_for(scene, bounces, settings.film_transparent,
                                                    trace_context.build_context)
        groups = GroupMap.of(self.ctx.lights, scene)  # light groups: every estimate also split by group
        if groups is not None:
            self.ctx = dataclasses.replace(self.ctx, groups=groups)
        # the light groups' names (one "Combined_<name>" pass each), () without
        self.group_names = () if groups is None else tuple(scene.light_groups.names)
        self.catchers = Catchers.of(self.ctx)  # shadow catchers (shadow_catcher.py), or None
        self.indirect = IndirectChoice(settings, bounces, methods.gi_auto(settings), self.ctx)
        self.gi = None  # gi.GISettings when the indirect light is resampled
        if settings.integrator == Integrator.RESTIR:
            cam = scene.camera
            self.spatial = methods.spatial_settings(settings, cam)
            if methods.gi_possible(settings):
                self.gi, self.gi_spatial = methods.gi_settings(settings, cam)
                unbiased = settings.bias_correction == "UNBIASED"
                self.gi_space = gi.GISpace(self.ctx.geom_accel if unbiased else None, settings.gi_target,
                                           len(self.group_names))
                lights, lamps = self.ctx.lights, self.ctx.scene.lamps
                # any change of what emits light (a lamp moved, switched, re-coloured) drops the GI history:
                # its cached radiance would be stale
                self.gi_light_key = fingerprint(lights.tri_verts, lights.rows_le, lights.power, lamps.sun_dir,
                                                lamps.sun_irradiance, lamps.falloff, lamps.falloff_smooth,
                                                self.ctx.scene.world_radiance,
                                                getattr(self.ctx.scene, "world_image", None))
        self._choose_direct()
        self.space = di.LightSpace(self.ctx.lights)
        # motion blur (geometry/motion_blur.py): each pass renders the scene posed at its own shutter time
        self.base_ctx, self.base_space = self.ctx, self.space
        blur = getattr(scene, "blur", None)
        self.blur = blur if blur is not None and blur.moves else None
        self.shutter_time = None  # the last pass's shutter time τ (None without motion blur)
        if self.blur is not None:
            self._blur_rows = self.blur.moving_rows(scene.geometry.instance)
            self._still = None  # (Accel, rows) of the triangles that do not move, built at the first pose
        self.build_seconds = time.perf_counter() - t0
        self.set_camera(scene.camera)
        if history is not None and history.fits(scene.camera):
            self.adopt_history(history)

    # -- methods ------------------------------------------------------------------------------------
    def _choose_direct(self) -> None:
        self.direct = methods.choose_direct(self.settings, self.ctx.lights, self.ctx.max_bounces,
                                            self.indirect.method == "RESTIR_GI")

    @property
    def method(self) -> str:
        """The direct method: "PATH" (path tracer) or one of di.DIRECT_METHODS."""
        return self.direct.method

    @property
    def candidates(self):
        """di.CandidateSettings when the direct light is resampled, else None."""
        return self.direct.candidates

    @property
    def resamples_direct(self) -> bool:
        """Whether the direct light is resampled (the film has reservoir passes)."""
        return self.candidates is not None

    @property
    def camera(self):
        """The camera the passes render from."""
        return self.ctx.scene.camera

    @property
    def instance_matrices(self):
        """The exported instances' object-to-world matrices (scene.export_stats), or None."""
        return getattr(self.ctx.scene, "export_stats", {}).get("instance_matrices")

    @property
    def indirect_method(self) -> str:
        return self.indirect.method

    @property
    def gi_auto(self) -> bool:
        return self.indirect.auto

    def gi_runs(self) -> bool:
        """ReSTIR GI runs in the next pass (Auto: while its last measurement says so)."""
        return self.gi is not None and (not self.gi_auto or self.indirect.method == "RESTIR_GI")

    # -- camera, history and film -------------------------------------------------------------------
    def adopt_history(self, history) -> None:
        """Reuse ``history`` (restir.history.TemporalHistory, from another frame or view of this scene or of an
        edited one) in the next first sample pass: its reservoirs are remapped to this light table (dropped
        when they cannot be) and its GI reservoirs dropped when anything that emits changed. Reprojection
        projects with the history's own camera, so its resolution may differ from this one's."""
        hist = history.remapped(self.ctx.lights)  # None: the lights cannot be mapped
        if hist is not None and hist.gi_res is not None and (self.gi is None or hist.gi_key != self.gi_light_key or
                                                             type(hist.gi_res) is not self.gi_space.kind):
            hist = dataclasses.replace(hist, gi_res=None, gi_terms=None)
        self.prev_history = hist

    def latest_history(self):
        """The newest temporal history: the current view's first pass's, else the one that pass would reuse."""
        return self.history if self.history is not None else self.prev_history

    def reuses_history(self) -> bool:
        """Whether the next first pass merges with a previous frame's (or view's) DI reservoirs."""
        h = self.prev_history
        return bool(self.settings.temporal_reuse and h is not None and h.res is not None)

    def move_camera(self, camera, frame: int) -> None:
        """Viewport navigation: render the same scene from ``camera`` (any resolution) as frame ``frame`` (keys
        the random streams, so a new view never repeats the last one's noise) and restart accumulation; the
        newest history is reprojected into the new view's first pass (temporal reuse, as between the frames
        of an animation with a moving camera)."""
        hist = self.latest_history()
        self.settings = dataclasses.replace(self.settings, frame=int(frame))
        self.indirect.frame = int(frame)
        self.set_camera(camera)
        if hist is not None and self.settings.temporal_reuse:
            self.prev_history = hist

    def set_motion(self, motion) -> None:
        """The scene's motion (scene.Motion) for the next pass's temporal reprojection."""
        self.ctx.scene.motion = motion

    def set_camera(self, camera) -> None:
        """Use another camera (same scene) and restart accumulation."""
        if getattr(self, "blur", None) is not None:  # back to the frame's own pose (the next pass poses again)
            self.ctx, self.space = self.base_ctx, self.base_space
        self.ctx.scene.camera = camera
        self._set_masks(camera)
        _x0, _y0, w, h = camera.window
        self.release()
        st = self.settings
        self.film = Film(w, h, self.gi is not None, st.denoise_data, self.film_zeros, st.use_adaptive_sampling,
                         self.group_names, film_mode(st, self.catchers is not None))
        # adaptive sampling: which pixels the next passes sample (pipeline/adaptive.py)
        self.adaptive = AdaptiveSampling(w, h, st.samples, st.adaptive_threshold, st.adaptive_min_samples) \
            if st.use_adaptive_sampling else None
        self.batches = BatchChoice(st)
        self._sample = None  # the pass to render where it is not the next one (independent_pass)
        self.boiling_dropped = 0  # reservoirs the boiling filter emptied since the camera was set
        self.gi_skipped = 0  # samples whose pass kept path-traced indirect light (GI_MIN_SHARE)
        self.reuse_stats = {}  # the last pass's temporal acceptance and confidence (diagnostics)
        self.used_tiles = False
        self._data = None
        self.prev_history = None
        self.history = None

    def _set_masks(self, camera) -> None:
        """The camera rays' masks (which pixels may see geometry, lamps, emitters) for ``camera`` in self.ctx."""
        self.coverage, self.coverage_reason, self.coverage_mask = coverage_mod.coverage(
            self.settings.coverage_samples, self.ctx.lights, self.ctx.scene.lamps, camera)
        self.masks = primary.CameraMasks(self.coverage_mask, coverage_mod.geometry_mask(self.ctx, camera),
                                         coverage_mod.lamp_mask(self.ctx, camera))

    def _pose(self, sample: int) -> None:
        """Motion blur: pose the scene at pass ``sample``'s shutter time (ShutterMotion.pass_time) for the pass;
        only the triangles that move are rebuilt (trace_context.moved_context)."""
        st, blur, base = self.settings, self.blur, self.base_ctx
        tau = blur.pass_time(st.seed, st.frame, sample, st.samples)
        posed = self.ctx if self.ctx is not base else None  # the last pass's pose: its arrays are overwritten
        scene = blur.scene_at(base.scene, tau, None if posed is None else posed.scene)
        if self._blur_rows.size:
            ctx = trace_context.moved_context(base, scene, self._blur_rows, self._still, posed)
            self._still = ctx.geom_accel.still_part()
        else:  # only the camera moves
            ctx = dataclasses.replace(base, scene=scene)
        self.ctx = ctx
        self.space = self.base_space if ctx.lights is base.lights else di.LightSpace(ctx.lights)
        if self.gi is not None:
            unbiased = st.bias_correction == "UNBIASED"
            self.gi_space = gi.GISpace(ctx.geom_accel if unbiased else None, st.gi_target, len(self.group_names))
        self._set_masks(scene.camera)
        self.shutter_time = tau

    @property
    def samples_done(self) -> int:
        return self.film.samples

    @property
    def converged(self) -> bool:
        """Adaptive sampling stopped every pixel: the frame needs no more passes."""
        return self.adaptive is not None and self.adaptive.finished

    def has_pass_data(self, key: str) -> bool:
        """Whether the film accumulates ``key`` (film.py lists the keys)."""
        return self.film.has(key)

    def sums(self, key: str):
        """The film's running sum ``key`` (film.FILM_DTYPE, over the samples done), or None where it is not kept."""
        return self.film.acc.get(key)

    def release(self) -> None:
        """Hand the film's accumulators back for the next frame's renderer (after :meth:`passes`; this renderer
        cannot accumulate any more)."""
        film = getattr(self, "film", None)
        if film is not None:
            film.release()

    def combined(self) -> np.ndarray:
        return self.film.combined()

    def mean(self, key: str) -> np.ndarray:
        return self.film.mean(key)

    def data_passes(self):
        """Depth (h, w, 1), Normal (h, w, 3) and Vector (h, w, 4) at pixel centres (data_passes.py)."""
        if self._data is None:  # at the frame's own time (motion blur: not at the last pass's)
            self._data = render_data_passes(self.base_ctx, self.settings.tile_pixels)
        return self._data

    def passes(self) -> dict:
        """All passes (see :class:`FrameResult`); float32, finite everywhere."""
        out = self.film.passes(self.candidates is not None)
        if self.settings.data_passes:
            out["Depth"], out["Normal"], out["Vector"] = (finite(a) for a in self.data_passes())
        return out

    # -- one sample pass ------------------------------------------------------------------------------
    def sample_pass(self, progress=None, should_stop=None, batch: int = 1, light_candidate_cap: int | None = None
                    ) -> bool:
        """Render the next sample pass (one path per pixel; ``batch`` per pixel where the pass can) into the film,
        with at most ``light_candidate_cap`` light candidates (viewport navigation). Returns False, keeping the film
        unchanged, when ``should_stop`` asked to stop part-way. Floating-point overflow from extreme scene values
        (radiance near export.limits.MAX_RADIANCE times a sharp BSDF) is not reported per operation: the film keeps
        only finite values (parallel.pool.quiet_float_errors)."""
        try:
            with quiet_float_errors():
                done = self._sample_pass(progress, should_stop, batch, light_candidate_cap)
        except Stopped:
            if self.team.size > 1:
                self.team.abort()  # the other processes of the team stop at their next barrier
            return False
        self.film.samples += done
        self._settle()
        return True

    def passes_independent(self) -> bool:
        """Whether the frame's next passes render the same whatever rendered the passes before them, so that they
        may render at the same time, each by another process (pipeline/spread.py): the first pass is done (it may
        reuse a history, probe and choose the methods) and no pass changes what the next one does: no motion blur
        (each pass poses the scene from the last pose), no Auto indirect choice that measures every pass it runs
        ReSTIR GI in. Adaptive sampling changes the passes only at its checks (:meth:`independent_until`)."""
        return self.samples_done > 0 and self.blur is None and not (self.gi_auto and self.gi_runs())

    def independent_until(self) -> int | None:
        """The sample count after which adaptive sampling's next check reads the film (None: no check is left):
        the independent passes end before the pass that reaches it, which renders with the check."""
        return None if self.adaptive is None else self.adaptive.next_check(self.samples_done)

    def _settle(self) -> None:
        """Fix the batch of the frame's later passes once they are independent (chosen again after each adaptive
        check, whose active pixels fill the chunks otherwise)."""
        if self.passes_independent():
            self.batches.settle(self._can_batch())

    def independent_pass(self, sample: int, batch: int, team, should_stop=None, progress=None) -> bool:
        """Render pass ``sample`` (``batch`` samples) alone, as ``team`` (parallel/team.Independent) orders it into
        the shared film, while other processes render other passes of the frame (:meth:`passes_independent` must
        hold); ``progress(fraction)`` as the pass's chunks finish. The film's sample count is left to the caller.
        Returns False when ``should_stop`` stopped it before it committed (the film then holds none of it)."""
        saved, self.team, self._sample = self.team, team, int(sample)
        try:
            with quiet_float_errors():
                self._sample_pass(progress, should_stop, batch, None)
        except Stopped:
            return False
        finally:
            self.team, self._sample = saved, None
        return True

    def batch_size(self, remaining: int) -> int:
        """Samples the next pass should render at once (at most ``remaining``; batches.BatchChoice), cut by adaptive
        sampling to end at its next check."""
        if not self._can_batch():
            return 1
        batch = self.batches.uncapped(remaining)
        return batch if self.adaptive is None else self.adaptive.cap(self.samples_done, batch)

    def _can_batch(self) -> bool:
        """Whether the next pass may render several samples at once: it keeps no per-pixel state (no reservoirs, no
        ReSTIR GI), measures nothing for Auto indirect (no probe; the first pass without a measurement probes) and
        is not motion-blurred (each sample at its own shutter time)."""
        if self.candidates is not None or self.gi_runs() or self.blur is not None:
            return False
        if self.gi is None or self.samples_done > 0:
            return True
        return self.indirect.measured and not self.indirect.probe_due()

    def _plan(self, batch: int, cap) -> PassPlan:
        """The pass's plan (plan.py), after the Auto indirect probe where nothing is measured yet."""
        st, ctx = self.settings, self.ctx
        s = self.samples_done if self._sample is None else self._sample
        if not self._can_batch():
            batch = 1
        if self.gi_auto and s == 0 and not self.indirect.measured:
            with self.clock.stage("probe"):  # nothing measured yet (a still, a first frame): measure before choosing
                self._measured(self.indirect.probe(ctx, st.seed, self.masks.may_hit, self._make_gi))
        gi_on = self.gi_runs()
        probe = self.gi_auto and not gi_on and s == 0 and self.indirect.start_first_pass()
        candidates = self.candidates
        resampled = candidates is not None
        if resampled and cap is not None and candidates.light_candidates > cap:
            candidates = dataclasses.replace(candidates, light_candidates=cap)
        world_resampled = resampled and candidates.world_resampled(ctx.lights)
        _x0, _y0, w, h = ctx.scene.camera.window
        hist = self.prev_history
        first_with_history = st.temporal_reuse and s == 0 and hist is not None
        return PassPlan(
            window_step=chunk_size(w * h, st.tile_pixels), partial=self.adaptive is not None and
            self.adaptive.active is not None,
            seed=st.seed, frame=st.frame, sample=s, batch=max(1, int(batch)), resampled=resampled,
            reusing=self.method == DirectMethod.RESTIR, temporal=first_with_history and hist.res is not None, gi=gi_on,
            gi_temporal=first_with_history and hist.gi_res is not None, probe=probe,
            glass_chains=st.integrator == Integrator.RESTIR and (resampled or gi_on), world_resampled=world_resampled,
            continuing=pathtracer.needs_continuation(ctx, resampled, world_resampled),
            strata=self.coverage if self.catchers is None else 1,  # coverage rays do not see catchers as matte
            candidates=candidates, light_tiles=bool(resampled and ctx.lights.tri_alias is not None
                                                    and candidates.tile_settings.wanted(w * h,
                                                                                        candidates.light_candidates)))

    def _make_gi(self, surf, first, block, filled: bool = False):
        return paths.gi_initial(self.gi, self.gi_space, surf, first, block, filled)

    def _measured(self, sums) -> None:
        """Auto indirect chooses again from the measured ``sums`` (IndirectChoice.update); the Auto direct method
        follows when its premise (GI or not) changed; both apply from the next pass on."""
        before = self.indirect.method
        self.reuse_stats.update(self.indirect.update(sums))
        if self.indirect.method != before and self.settings.direct_method == DirectMethod.AUTO:
            self._choose_direct()

    def _sample_pass(self, progress, should_stop, batch: int, cap) -> int:
        """One pass of ``plan.batch`` samples through the stages. Returns the samples rendered."""
        if self.blur is not None:
            self._pose(self.samples_done)
        st, ctx, clock, team = self.settings, self.ctx, self.clock, self.team
        plan = self._plan(batch, cap)
        _x0, _y0, w, h = ctx.scene.camera.window
        active = None if self.adaptive is None else self.adaptive.pixels()
        chunks = make_chunks(spans(w * h, st.tile_pixels), plan.batch) if active is None else \
            make_chunks([active[sl] for sl in spans(len(active), st.tile_pixels)], plan.batch)
        team.begin_pass(first=plan.sample == 0, chunks=len(chunks))
        mine = own(chunks, team)  # the chunks this process computes (all of them when it renders alone)
        # chunk tasks of the pass, for progress (reuse maps over about as many surface chunks per pass)
        chunk_stages = 4 + int(plan.resampled) + (int(self.spatial.passes) + 1 if plan.reusing else 0) + \
            (int(self.gi.passes) + 1 if plan.gi else 0)
        run = PassRunner(plan, Progress(progress, should_stop, len(mine) * chunk_stages), clock, st.tile_pixels,
                         team)

        with run.stage("primary"):
            run.map_chunks(lambda c: primary.primary(ctx, plan, self.masks, c, self.catchers), chunks, 0)
            n_surf = place(chunks, team)
            self.batches.measured(n_surf, len(chunks), plan.batch)
        candidates = plan.candidates
        if plan.resampled:
            self.reuse_stats["light_candidates"] = candidates.light_candidates
        if plan.light_tiles:
            with run.stage("initial"):
                candidates = direct.with_light_tiles(ctx, plan, chunks, st.light_sampler, team)
            self.used_tiles = True
        # the frame's target terms, one (width, surfaces) block the chunks write into (reuse gathers from it)
        rows = width(ctx.anisotropic, ctx.sheen)
        terms = team.empty((rows, n_surf), np.float32) if plan.resampled else None
        # ReSTIR GI's target terms: the same, with the specular lobe off at glossy primary surfaces
        gi_terms = team.empty((rows, n_surf), np.float32) if plan.gi or plan.probe else None
        if plan.resampled:
            with run.stage("initial"):
                run.map_chunks(lambda c: direct.initial(ctx, plan, candidates, terms, c), chunks, 1)
        with run.stage("paths"):
            run.map_chunks(lambda c: paths.paths(ctx, plan, terms, gi_terms, self._make_gi, c), chunks, 1)
        gi_reused = paths.gi_outcome(plan, chunks, self.team, self.reuse_stats,
                                     self._measured if self.gi_auto else None)
        if self.gi is not None and not gi_reused:
            self.gi_skipped += plan.batch
        gb = res = gi_res = gb_gi = gi_history = None
        if plan.reusing or gi_reused:
            with run.stage("gbuffer"):
                gb = primary.gbuffer(ctx, chunks, terms if plan.reusing else gi_terms, team)
        if plan.reusing:
            with run.stage("gbuffer"):
                res = frame_reservoirs(chunks, "res", di.DIReservoirs, len(gb), team)
            res, dropped = reuse.reuse_di(run, st, ctx, self.space, self.spatial, gb, res, self.prev_history,
                                          self.reuse_stats)
            self.boiling_dropped += dropped
            hand_back(mine, "res", res)
        if gi_reused:
            with run.stage("gbuffer"):
                gb_gi = gb.with_terms(ShadingTerms(gi_terms))
                gi_res = frame_reservoirs(chunks, "gi_res", self.gi_space.kind, len(gb), team)
            gi_res, gi_history = reuse.reuse_gi(run, st, ctx, self.gi, self.gi_space, self.gi_spatial, gb_gi, gi_res,
                                                self.prev_history, self.reuse_stats)
            hand_back(mine, "gi_res", gi_res)
        if plan.sample == 0 and gb is not None and self.keeps_history:
            self._keep_history(run, gb, res, gb_gi, gi_history, gi_reused)
        unbiased = st.bias_correction == "UNBIASED"
        with run.stage("shade"):
            run.map_chunks(lambda c: shade.shade(ctx, plan, gi_reused, unbiased, c, self.catchers), chunks, 2)
        team.publish_costs()
        team.commit()  # the pass is shaded: from here on it is not stopped (the film takes all of it or, stopped
        run.stop.should_stop = None  # before, none)
        with run.stage("passes"):
            world_to_cam = np.ascontiguousarray(ctx.scene.camera.cam_to_world[:3, :3].T, dtype=np.float32)
            self.film.accumulate(mine, plan.resampled, world_to_cam, run.stop, team.in_order)
        if self.adaptive is not None and self.adaptive.due(plan.sample + plan.batch):
            team.barrier()  # every process's samples are in the film
            self.adaptive.check(self.film, plan.sample + plan.batch)
            self.batches.unsettle()  # the active pixels changed: the batch is chosen again
        return plan.batch

    def _keep_history(self, run, gb, res, gb_gi, gi_history, gi_reused: bool) -> None:
        """The next frame's history from this first pass; confidence at most the cap, so no reused M exceeds it."""
        st, lights = self.settings, self.ctx.lights
        self.team.kept()
        cap = st.confidence_cap
        self.history = TemporalHistory(
            gb, None if res is None else run.per_span(res, lambda r: r.replace(M=np.minimum(r.M, cap))),
            self.ctx.scene.camera, lights.signature, st.frame, lights.light_uid, lights.uid_space,
            gi_res=None if gi_history is None else run.per_span(gi_history, lambda r: reuse.age_history(self.gi, r)),
            gi_terms=None if gb_gi is None else gb_gi.terms, gi_key=self.gi_light_key if gi_reused else None)
