//! The perf bench's draw timings: the billboards, the splat, the tiles (each stage and
//! each resolve) and the tonemap, on one filled simulation.

use super::*;

/// The draw paths' GPU times on one simulation.
#[derive(Clone, Debug, serde::Serialize)]
pub struct DrawCosts {
    /// Billboard draw, ms (None when skipped).
    pub billboard_ms: Option<f64>,
    /// Splat draw (clear + splat + resolve), ms.
    pub splat_ms: f64,
    /// Tile draw (project, bin, shade and the resolve), ms (None when the target is larger
    /// than the tiles' bins, or the device has no tile rasteriser).
    pub tiles_ms: Option<f64>,
    /// The tile draw's project alone and project + bin, ms (the shade and resolve are the
    /// rest of `tiles_ms`).
    pub tiles_stages_ms: Option<[f64; 2]>,
    /// The tiles' resolve alone, ms: by compute (None where the adapter cannot; the tile
    /// draw uses it where it can, as the editor does) and by a draw.
    pub tiles_resolve_ms: Option<(Option<f64>, f64)>,
    /// Tonemap composite, ms.
    pub composite_ms: f64,
    /// The path Auto picks for this scene.
    pub auto_path: &'static str,
}

/// Times every draw path over the particles of `sim`.
pub(super) fn draw_costs(
    ctx: &GpuContext,
    opts: &PerfOptions,
    n: u64,
    (sim, effect): (&GpuSim, &Effect),
    timer: &GpuTimer,
) -> Result<DrawCosts, SimError> {
    let lib = ShaderLibrary::embedded();
    let mut frame = FrameResources::new(ctx);
    frame.allow_tiles = TilePass::supported(&ctx.device);
    let mut sort = SortPass::new(ctx, &lib)?;
    let mut billboard = BillboardPass::new(ctx, &lib, &frame, DrawTarget::hdr())?;
    let mut splat = SplatPass::new(ctx, &lib, &frame, DrawTarget::hdr())?;
    let mut tiles = frame
        .allow_tiles
        .then(|| TilePass::new(ctx, &lib, &frame, DrawTarget::hdr()))
        .transpose()?;
    let tonemap = TonemapPass::new(ctx, &lib)?;
    let camera = OrbitCamera::from_hint(&effect.camera);
    let size = opts.size;
    let targets = crate::render::Targets::new(ctx, size);
    let scene = [Some(crate::render::Scene { sim, effect })];
    let items = frame.prepare(ctx, &[&scene], &camera.view(size), 1.0, &mut sort, None);
    let mut uploads = crate::gpu::Uploads::new(&ctx.device);
    let mut enc = ctx.device.create_command_encoder(&Default::default());
    frame.upload_looks(&mut uploads, &mut enc);
    uploads.finish(&enc);
    ctx.queue.submit([enc.finish()]);
    let auto_path = if items.iter().all(|d| d.splat) {
        "splat"
    } else if items.iter().all(|d| d.tiles) {
        "tiles"
    } else {
        "billboard"
    };
    let with_path = |splat: bool, tiles: bool| -> Vec<DrawItem> {
        items
            .iter()
            .map(|d| DrawItem {
                splat,
                tiles,
                ..d.clone()
            })
            .collect()
    };
    let (all_billboard, all_splat) = (with_path(false, false), with_path(true, false));
    let all_tiles = with_path(false, true);
    billboard.prepare(ctx, &all_billboard, &frame.sprites.sampler, false);
    let billboard_ms = (n <= opts.billboard_limit).then(|| {
        time_median(timer, ctx, opts.repeats.min(3), |enc| {
            let mut pass = load_hdr_pass(enc, &targets.hdr_view);
            billboard.draw(&mut pass, &frame, &all_billboard, |_| true);
        })
    });
    // Splat: clear + compute splat + its resolve into the HDR target (by compute where
    // the adapter can, as the editor does).
    let splat_ms = {
        let mut samples = Vec::new();
        for _ in 0..opts.repeats {
            samples.push(timer.time(ctx, |enc| {
                splat.splat(ctx, enc, &frame, &all_splat, size, None);
                if !splat.resolve_into(ctx, enc, &frame, &targets.hdr_view, size) {
                    splat.resolve(&mut load_hdr_pass(enc, &targets.hdr_view), &frame);
                }
            }));
        }
        median(&mut samples)
    };
    let tiles = tiles.as_mut();
    let (tiles_ms, tiles_stages_ms, tiles_resolve_ms) =
        tile_costs(ctx, opts, timer, tiles, (&frame, &all_tiles), &targets);
    // Composite: the tonemap.
    let composite_ms = time_median(timer, ctx, opts.repeats, |enc| {
        tonemap.record(
            ctx,
            enc,
            &targets.hdr_view,
            None,
            None,
            None,
            (&targets.ldr_view, targets.size),
            1.0,
        );
    });
    Ok(DrawCosts {
        billboard_ms,
        splat_ms,
        tiles_ms,
        tiles_stages_ms,
        tiles_resolve_ms,
        composite_ms,
        auto_path,
    })
}

/// The tile times: all stages, project and bin alone, and each resolve alone.
type TileCosts = (Option<f64>, Option<[f64; 2]>, Option<(Option<f64>, f64)>);

/// Project, bin, shade and the resolve into the HDR target (by compute where the adapter
/// can, as the composite does); `None`s where the tiles are off or do not fit.
fn tile_costs(
    ctx: &GpuContext,
    opts: &PerfOptions,
    timer: &GpuTimer,
    tiles: Option<&mut TilePass>,
    (frame, all_tiles): (&FrameResources, &[DrawItem]),
    targets: &crate::render::Targets,
) -> TileCosts {
    let size = opts.size;
    let (mut tiles_stages_ms, mut tiles_resolve_ms) = (None, None);
    let hdr = &targets.hdr_view;
    let mut uploads = crate::gpu::Uploads::new(&ctx.device);
    let tiles_ms = tiles.and_then(|t| {
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        let fits = t.record(ctx, (&mut enc, &mut uploads), frame, all_tiles, size, None);
        uploads.finish(&enc);
        ctx.queue.submit([enc.finish()]);
        let resolve = |t: &mut TilePass, enc: &mut wgpu::CommandEncoder| {
            if !t.resolve_into(ctx, enc, frame, hdr, size) {
                t.resolve(&mut load_hdr_pass(enc, hdr), frame);
            }
        };
        let mut time = |t: &mut TilePass, stages| {
            t.set_stages(stages);
            time_median(timer, ctx, opts.repeats, |enc| {
                t.record(ctx, (enc, &mut uploads), frame, all_tiles, size, None);
                uploads.finish(enc);
                resolve(t, enc);
            })
        };
        fits.then(|| {
            tiles_stages_ms = Some([TileStages::Project, TileStages::Bin].map(|s| time(t, s)));
            let all = time(t, TileStages::All);
            // The last record stays shaded: each resolve timed alone.
            let by_compute = t
                .can_resolve_into(size)
                .then(|| time_median(timer, ctx, opts.repeats, |enc| resolve(t, enc)));
            let by_draw = time_median(timer, ctx, opts.repeats, |enc| {
                t.resolve(&mut load_hdr_pass(enc, hdr), frame);
            });
            tiles_resolve_ms = Some((by_compute, by_draw));
            all
        })
    });
    (tiles_ms, tiles_stages_ms, tiles_resolve_ms)
}
