//! The last two frame steps: paint egui's output (step 4) and present it in the window
//! (step 5), with the screenshot `--screenshot` asks for.
//!
//! With a retained window image (the software profile: see `retained.rs`) the UI is
//! painted into that image — only over the viewport while the panel is unchanged — and the
//! image is copied to the window's frame; otherwise it is painted into the frame itself.

use std::path::PathBuf;

use anyhow::Context as _;
use egui::ClippedPrimitive;

use crate::editor::window::gfx::Gfx;
use crate::editor::window::retained::{Repaint, RetainedImage};
use crate::editor::window::screenshot::Screenshot;

/// The viewport's background colour (gamma-encoded, as egui's colours are).
const VIEWPORT_BACKGROUND: egui::Color32 = egui::Color32::from_rgb(9, 9, 11);

/// [`VIEWPORT_BACKGROUND`] as the UI pass's clear colour.
const VIEWPORT_CLEAR: wgpu::Color = wgpu::Color {
    r: VIEWPORT_BACKGROUND.r() as f64 / 255.0,
    g: VIEWPORT_BACKGROUND.g() as f64 / 255.0,
    b: VIEWPORT_BACKGROUND.b() as f64 / 255.0,
    a: 1.0,
};

/// The UI ready to present: meshes uploaded, textures updated, what to paint over what.
pub(crate) struct PaintedUi {
    encoder: wgpu::CommandEncoder,
    /// Command buffers the painter needs submitted before the frame's.
    callbacks: Vec<wgpu::CommandBuffer>,
    jobs: Vec<ClippedPrimitive>,
    screen: egui_wgpu::ScreenDescriptor,
    /// A clear to the viewport's background, or what the retained image holds.
    load: wgpu::LoadOp<wgpu::Color>,
    /// The retained image painted into, when there is one.
    retained: Option<RetainedImage>,
    /// Textures egui no longer needs (freed after the submit).
    free: Vec<egui::TextureId>,
}

impl Gfx {
    /// Step 4, paint: egui's texture updates, its meshes tessellated and uploaded (with a
    /// retained image: only those over the viewport while the panel is unchanged).
    pub(crate) fn paint_ui(&mut self, ui: egui::FullOutput) -> PaintedUi {
        let mut encoder = self
            .ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("editor::ui"),
            });
        let all_jobs = self.egui_ctx.tessellate(ui.shapes, ui.pixels_per_point);
        let textures = ui.textures_delta;
        for (id, deltas) in &textures.set {
            for delta in deltas {
                self.ui_painter
                    .update_texture(&self.ctx.device, &self.ctx.queue, *id, delta);
            }
        }
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [self.config.width, self.config.height],
            pixels_per_point: ui.pixels_per_point,
        };
        let textures_changed = !textures.set.is_empty() || !textures.free.is_empty();
        let size = (self.config.width, self.config.height);
        let (retained, repaint) = match self.retained.as_mut() {
            Some(r) => {
                let image = r.image(&self.ctx.device, size, self.config.format).clone();
                let repaint = r.plan(
                    &all_jobs,
                    self.live_rect,
                    screen.size_in_pixels,
                    textures_changed,
                    VIEWPORT_BACKGROUND,
                    self.viewport_texture,
                );
                (Some(image), repaint)
            }
            None => (None, Repaint::Full),
        };
        let (jobs, load) = match repaint {
            Repaint::Live(jobs) => (jobs, wgpu::LoadOp::Load),
            Repaint::Full => (all_jobs, wgpu::LoadOp::Clear(VIEWPORT_CLEAR)),
        };
        let callbacks = self.ui_painter.prepare(
            &self.ctx.device,
            &self.ctx.queue,
            &mut encoder,
            &jobs,
            &screen,
        );
        self.profiler.end_stage(&self.ctx);
        PaintedUi {
            encoder,
            callbacks,
            jobs,
            screen,
            load,
            retained,
            free: textures.free.iter().copied().collect(),
        }
    }

    /// Step 5, present: paints the UI into the window's frame (or into the retained
    /// image, then copied to the frame), records the screenshot when `screenshot` names
    /// one, submits and presents. Returns the screenshot to read back, if one was taken
    /// (`None` also when the window had no frame to give: the caller tries again).
    pub(crate) fn present(
        &mut self,
        mut ui: PaintedUi,
        instance: &wgpu::Instance,
        screenshot: Option<PathBuf>,
    ) -> anyhow::Result<Option<Screenshot>> {
        let frame = self.acquire_frame(instance)?;
        let mut shot = None;
        if let Some(frame) = &frame {
            // Where the UI is painted, and the image the screenshot copies.
            let (view, image) = match &ui.retained {
                Some(r) => (r.view.clone(), r.texture.clone()),
                None if self.surface_can_copy || screenshot.is_none() => (
                    frame.texture.create_view(&Default::default()),
                    frame.texture.clone(),
                ),
                // The window's frame cannot be copied from: paint the UI twice, the second
                // time into an image that can.
                None => {
                    let view = frame.texture.create_view(&Default::default());
                    self.ui_painter
                        .paint(&mut ui.encoder, &view, &ui.jobs, &ui.screen, ui.load);
                    let offscreen = self.offscreen_target(frame);
                    (offscreen.create_view(&Default::default()), offscreen)
                }
            };
            self.ui_painter
                .paint(&mut ui.encoder, &view, &ui.jobs, &ui.screen, ui.load);
            if ui.retained.is_some() {
                ui.encoder.copy_texture_to_texture(
                    image.as_image_copy(),
                    frame.texture.as_image_copy(),
                    image.size(),
                );
            }
            shot =
                screenshot.map(|path| Screenshot::record(&self.ctx, &mut ui.encoder, &image, path));
        } else if let Some(r) = self.retained.as_mut() {
            // Nothing was painted: the image no longer matches the panel.
            r.invalidate();
        }
        self.ctx
            .queue
            .submit(ui.callbacks.into_iter().chain([ui.encoder.finish()]));
        self.profiler.end_stage(&self.ctx);
        if let Some(frame) = frame {
            self.window.pre_present_notify();
            self.ctx.queue.present(frame);
        }
        self.profiler.end_stage(&self.ctx);
        for id in &ui.free {
            self.ui_painter.free_texture(id);
        }
        Ok(shot)
    }

    /// The window's next frame; `None` when it has none to give now (outdated, lost,
    /// occluded: the surface is reconfigured or recreated for the next frame).
    fn acquire_frame(
        &mut self,
        instance: &wgpu::Instance,
    ) -> anyhow::Result<Option<wgpu::SurfaceTexture>> {
        Ok(match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(f) => Some(f),
            wgpu::CurrentSurfaceTexture::Suboptimal(f) => {
                // Draw this one; reconfigure for the next.
                self.resize(self.config.width, self.config.height);
                Some(f)
            }
            wgpu::CurrentSurfaceTexture::Outdated => {
                let size = self.window.inner_size();
                self.resize(size.width, size.height);
                None
            }
            wgpu::CurrentSurfaceTexture::Lost => {
                self.surface = instance
                    .create_surface(self.window.clone())
                    .context("recreating the lost window surface")?;
                self.surface.configure(&self.ctx.device, &self.config);
                None
            }
            wgpu::CurrentSurfaceTexture::Timeout
            | wgpu::CurrentSurfaceTexture::Occluded
            | wgpu::CurrentSurfaceTexture::Validation => None,
        })
    }

    /// An image like the window's frame that can be copied from (for a screenshot).
    fn offscreen_target(&self, frame: &wgpu::SurfaceTexture) -> wgpu::Texture {
        crate::gpu::texture_2d(
            &self.ctx.device,
            "editor::screenshot_target",
            (frame.texture.width(), frame.texture.height()),
            1,
            self.config.format,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        )
    }
}
