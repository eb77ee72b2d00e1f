//! [`Composite`]: the host that the editor's viewport, `ignis render` and the headless
//! tests are — a client of the public [`Player`] API like any embedding program. It
//! draws the player's layers into an HDR target of its own (the soft ones at reduced
//! resolution when the preset or draft quality asks), then its bloom and tonemap into a
//! display image.

use crate::gpu::{GpuContext, TextureReadback};
use crate::render::bloom::BloomPass;
use crate::render::test_scene::TestScene;
use crate::render::{
    Camera, HDR_FORMAT, Targets, TonemapPass, ensure_layer, load_hdr_pass, reduced,
};
use crate::runtime::{Layers, Player, PlayerSettings, Resolves};
use crate::shaders::{ShaderError, ShaderLibrary};
use crate::sim::gpu_sim::{SimError, map_read};

/// HDR target, reduced-resolution layers, bloom and tonemap around a [`Player`].
pub struct Composite {
    /// The tonemap pass.
    pub tonemap: TonemapPass,
    /// The bloom passes (recorded only when the effect has bloom).
    pub bloom: BloomPass,
    /// Zeroes the HDR target (a compute pass) before the particles' pass.
    pub clear: crate::render::clear::ClearPass,
    targets: Option<Targets>,
    /// Exposure multiplier applied before tonemapping (times the effect's own).
    pub exposure: f32,
    /// Draft quality (the editor's default on software adapters): the glow layer
    /// ([`Layers::GLOW`], e.g. flame tongues) is drawn at half resolution into a layer
    /// the bloom's prefilter and the tonemap read — a quarter of its fill; the blended
    /// layer at half the resolution `post.alpha_downscale` asks for.
    pub draft: bool,
    /// The reduced-resolution target of the blended layer (`post.alpha_downscale`).
    alpha_layer: Option<((u32, u32), wgpu::TextureView)>,
    /// The half-resolution target of the glow layer (draft).
    glow_layer: Option<((u32, u32), wgpu::TextureView)>,
    /// Draw the test scene's props before the particles and hand the player their depth
    /// (the editor's View setting): the layers are then all drawn at full resolution,
    /// where their soft edges read the depth.
    pub test_scene: bool,
    scene: TestScene,
    /// The scene was drawn into the HDR target this frame (it is not cleared again).
    scene_drawn: bool,
    /// Apply the effect's heat haze (on by default; the editor's View setting).
    pub heat_haze: bool,
    /// The HDR image refracted by heat haze (made on first need).
    haze_copy: Option<((u32, u32), wgpu::TextureView)>,
    /// This frame's image is `haze_copy` (heat haze was applied).
    hazed: bool,
}

impl Composite {
    /// Builds the composite's pipelines from `lib`.
    pub fn new(ctx: &GpuContext, lib: &ShaderLibrary) -> Result<Self, ShaderError> {
        Ok(Self {
            tonemap: TonemapPass::new(ctx, lib)?,
            bloom: BloomPass::new(ctx, lib)?,
            clear: crate::render::clear::ClearPass::new(ctx, lib)?,
            targets: None,
            exposure: 1.0,
            draft: false,
            alpha_layer: None,
            glow_layer: None,
            test_scene: false,
            scene: TestScene::new(ctx, lib)?,
            scene_drawn: false,
            heat_haze: true,
            haze_copy: None,
            hazed: false,
        })
    }

    /// The settings of a player that draws into this composite.
    pub fn player_settings() -> PlayerSettings {
        PlayerSettings::new(HDR_FORMAT)
    }

    /// Rebuilds the pipelines built from `entry` (one of [`COMPOSITE_SHADERS`]), keeping
    /// the old ones on error.
    pub fn reload_shader(
        &mut self,
        ctx: &GpuContext,
        lib: &ShaderLibrary,
        entry: &str,
    ) -> Result<(), ShaderError> {
        match entry {
            "tonemap.wgsl" => self.tonemap.rebuild(ctx, lib),
            "bloom.wgsl" => self.bloom.rebuild(ctx, lib),
            "clear.wgsl" => self.clear.rebuild(ctx, lib),
            "test_scene.wgsl" => TestScene::new(ctx, lib).map(|s| self.scene = s),
            _ => Ok(()),
        }
    }

    /// The targets, (re)created at `size` when needed.
    pub fn targets(&mut self, ctx: &GpuContext, size: (u32, u32)) -> &Targets {
        if self.targets.as_ref().is_some_and(|t| t.size != size) {
            self.targets = None;
        }
        self.targets.get_or_insert_with(|| Targets::new(ctx, size))
    }

    /// The targets of the last frame, if any.
    pub fn targets_ref(&self) -> Option<&Targets> {
        self.targets.as_ref()
    }

    /// Records `player`'s frame for `camera` (its compute work, then its layers into the
    /// HDR target) and the bloom and tonemap into the display image.
    pub fn record(
        &mut self,
        ctx: &GpuContext,
        enc: &mut wgpu::CommandEncoder,
        player: &mut Player,
        camera: &Camera,
    ) {
        let depth = self.draw_scene(ctx, enc, camera);
        self.record_player(enc, player, camera, depth.as_ref());
        self.draw(ctx, enc, player, camera);
    }

    /// The player's record for `camera` (sampling `depth`, the scene's), told first which
    /// layers this composite will draw at reduced resolution ([`Composite::reduced_layers`]).
    pub fn record_player(
        &self,
        enc: &mut wgpu::CommandEncoder,
        player: &mut Player,
        camera: &Camera,
        depth: Option<&wgpu::TextureView>,
    ) {
        player.set_reduced_layers(self.reduced_layers(player.effect()));
        player.record_sampling(enc, camera, depth);
    }

    /// With [`Composite::test_scene`] on, clears the HDR target and draws the props into
    /// it and into their depth, which it returns for the player; otherwise nothing.
    pub fn draw_scene(
        &mut self,
        ctx: &GpuContext,
        enc: &mut wgpu::CommandEncoder,
        camera: &Camera,
    ) -> Option<wgpu::TextureView> {
        if !self.test_scene {
            return None;
        }
        let targets = self.targets(ctx, camera.size_px());
        let (hdr, size) = (targets.hdr_view.clone(), targets.size);
        self.clear.record(ctx, enc, &hdr, size);
        self.scene_drawn = true;
        Some(self.scene.record(ctx, enc, &hdr, camera))
    }

    /// [`Composite::record`] after the player's `record` for `camera` (timed apart by
    /// the editor): its layers into the HDR target, then the bloom and tonemap.
    pub fn draw(
        &mut self,
        ctx: &GpuContext,
        enc: &mut wgpu::CommandEncoder,
        player: &mut Player,
        camera: &Camera,
    ) {
        let layered = self.draw_particles(ctx, enc, player, camera);
        self.apply_haze(ctx, enc, player);
        self.post(ctx, enc, player, layered);
    }

    /// Heat haze over the HDR target (the scene and the particles at full resolution):
    /// a copy of it refracted back into it by the player's haze layers.
    pub fn apply_haze(
        &mut self,
        ctx: &GpuContext,
        enc: &mut wgpu::CommandEncoder,
        player: &mut Player,
    ) {
        let on = self.heat_haze && player.has_haze();
        let Some(targets) = self.targets.as_ref().filter(|_| on) else {
            return;
        };
        let (hdr, size) = (targets.hdr_view.clone(), targets.size);
        ensure_layer(ctx, &mut self.haze_copy, "Composite::haze_copy", size);
        let Some((_, refracted)) = &self.haze_copy else {
            return;
        };
        // The HDR image refracted into a second one (every pixel written by compute),
        // which the bloom and tonemap then read: no copy of the frame (a texture copy of
        // a 4K image took ~1.3 ms on the H200).
        match player.apply_haze(enc, &hdr, refracted) {
            Ok(applied) => self.hazed = applied,
            Err(e) => log::warn!("heat haze: {e}"),
        }
    }

    /// The HDR image the bloom and tonemap read: the refracted one after heat haze.
    fn shown_hdr(&self) -> Option<&wgpu::TextureView> {
        match (&self.haze_copy, self.hazed) {
            (Some((_, refracted)), true) => Some(refracted),
            _ => self.targets.as_ref().map(|t| &t.hdr_view),
        }
    }

    /// The layers this composite draws at reduced resolution for `effect` (none over the
    /// test scene, whose depth the soft edges read at full resolution): the blended one
    /// when `post.alpha_downscale` (or draft) asks, the glow (at half resolution) when
    /// `post.glow_downscale` or draft does. The player is told
    /// before its record ([`Player::set_reduced_layers`]).
    pub fn reduced_layers(&self, effect: &crate::effect::Effect) -> Layers {
        let mut layers = Layers::NONE;
        if self.test_scene {
            return layers;
        }
        if self.alpha_downscale(effect) > 1 {
            layers |= Layers::BLENDED;
        }
        if self.draft || effect.post.glow_downscale > 1 {
            layers |= Layers::GLOW;
        }
        layers
    }

    /// The blended layer's reduction: the preset's, halved again in draft (soft smoke
    /// hides it).
    fn alpha_downscale(&self, effect: &crate::effect::Effect) -> u32 {
        effect.post.alpha_downscale.clamp(1, 4) << u32::from(self.draft)
    }

    /// The particle draws of [`Composite::draw`] (into the HDR target and the reduced
    /// layers); returns the layers drawn into a layer of their own, for [`Composite::post`].
    pub fn draw_particles(
        &mut self,
        ctx: &GpuContext,
        enc: &mut wgpu::CommandEncoder,
        player: &mut Player,
        camera: &Camera,
    ) -> Layers {
        let size = self.targets(ctx, camera.size_px()).size;
        let drawn = player.drawn_layers();
        let reduce = self.reduced_layers(player.effect());
        let mut layered = Layers::NONE;
        // The blended layer at reduced resolution, added in the tonemap.
        if reduce.contains(Layers::BLENDED) && drawn.contains(Layers::BLENDED) {
            let low = reduced(size, self.alpha_downscale(player.effect()));
            ensure_layer(ctx, &mut self.alpha_layer, "Composite::alpha_layer", low);
            if let Some((_, view)) = &self.alpha_layer {
                self.clear.record(ctx, enc, view, low);
                player.draw_layers(&mut load_hdr_pass(enc, view), Layers::BLENDED);
                layered |= Layers::BLENDED;
            }
        }
        if reduce.contains(Layers::GLOW) && drawn.contains(Layers::GLOW) {
            let half = reduced(size, 2);
            ensure_layer(ctx, &mut self.glow_layer, "Composite::glow_layer", half);
            if let Some((_, view)) = &self.glow_layer {
                self.clear.record(ctx, enc, view, half);
                player.draw_layers(&mut load_hdr_pass(enc, view), Layers::GLOW);
                layered |= Layers::GLOW;
            }
        }
        if let Some(targets) = self.targets.as_ref() {
            let (view, size) = (&targets.hdr_view, targets.size);
            if !std::mem::take(&mut self.scene_drawn) {
                self.clear.record(ctx, enc, view, size);
            }
            // The tiles are resolved by compute where the adapter can (between the
            // blended billboards under them and the light over them), else drawn; so is
            // the splat's light (after the rest: it is added). Both are the light layer's,
            // which is never reduced: it is always drawn here.
            let main = Layers::ALL.without(layered);
            let mut drawn = Resolves::DRAWN;
            drawn.splat = !player.splat_resolvable_into(size);
            if player.tiles_resolvable_into(size) {
                if player.draws_under_tiles(main) {
                    player.draw_under_tiles(&mut load_hdr_pass(enc, view), main);
                }
                drawn.tiles = !player.resolve_tiles_into(enc, view, size);
                player.draw_over_tiles(&mut load_hdr_pass(enc, view), main, drawn);
            } else {
                let mut pass = load_hdr_pass(enc, view);
                player.draw_under_tiles(&mut pass, main);
                player.draw_over_tiles(&mut pass, main, drawn);
            }
            if !drawn.splat {
                player.resolve_splat_into(enc, view, size);
            }
        }
        layered
    }

    /// The bloom and tonemap of [`Composite::draw`] after [`Composite::draw_particles`]
    /// (`layered`: what it returned).
    pub fn post(
        &mut self,
        ctx: &GpuContext,
        enc: &mut wgpu::CommandEncoder,
        player: &Player,
        layered: Layers,
    ) {
        let hdr = self.shown_hdr().cloned();
        self.hazed = false;
        let (Some(targets), Some(hdr)) = (self.targets.as_ref(), hdr) else {
            return;
        };
        let post = player.effect().post.clone();
        let low_alpha = layer_view(&self.alpha_layer, layered.contains(Layers::BLENDED));
        let glow = layer_view(&self.glow_layer, layered.contains(Layers::GLOW));
        // The glow layer joins the image in the bloom's prefilter and in the tonemap
        // (upsampled bilinearly there): no pass of its own.
        let bloom = post.bloom.as_ref().and_then(|b| {
            let view = self
                .bloom
                .record(ctx, enc, &hdr, glow, targets.size, b, self.draft)?;
            Some((view, b.intensity))
        });
        self.tonemap.record(
            ctx,
            enc,
            &hdr,
            bloom,
            low_alpha,
            glow,
            (&targets.ldr_view, targets.size),
            self.exposure * post.exposure,
        );
    }

    /// Renders `player`'s frame for `camera` and reads it back as an RGBA8 image
    /// (blocking).
    pub fn render_image(
        &mut self,
        ctx: &GpuContext,
        player: &mut Player,
        camera: &Camera,
    ) -> Result<image::RgbaImage, SimError> {
        let mut enc = ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("Composite::render_image"),
            });
        self.record(ctx, &mut enc, player, camera);
        let Some(targets) = self.targets.as_ref() else {
            return Err(SimError::Readback("no render target".into()));
        };
        let copy =
            TextureReadback::record(&ctx.device, &mut enc, &targets.ldr, "Composite::readback");
        ctx.queue.submit([enc.finish()]);
        let bytes = map_read(ctx, &copy.buffer)?;
        let rows = copy
            .rows(&bytes)
            .ok_or_else(|| SimError::Readback("the image readback is too short".into()))?;
        let (w, h) = copy.size;
        let pixels = rows.concat();
        image::RgbaImage::from_raw(w, h, pixels)
            .ok_or_else(|| SimError::Readback("image size mismatch".into()))
    }
}

/// The view of a layer target, if it was drawn this frame.
fn layer_view(
    slot: &Option<((u32, u32), wgpu::TextureView)>,
    drawn: bool,
) -> Option<&wgpu::TextureView> {
    slot.as_ref().filter(|_| drawn).map(|(_, v)| v)
}
