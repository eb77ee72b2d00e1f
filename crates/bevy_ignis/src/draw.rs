//! Drawing in Bevy's 3D frame: after the main transparent pass of each 3D camera, every
//! player of that view records its steps, sort and splat into Bevy's encoder and draws
//! into the view's colour target (multisampled with its resolve, when MSAA is on),
//! tested against the view's reversed-Z depth, which it also samples for soft edges.

use bevy::prelude::*;
use bevy::render::camera::ExtractedCamera;
use bevy::render::diagnostic::RecordDiagnostics;
use bevy::render::render_resource::TextureUsages;
use bevy::render::renderer::{FlushCommands, RenderContext, ViewQuery};
use bevy::render::view::{ExtractedView, Msaa, ViewDepthStencilTexture, ViewTarget};
use ignis::HostTargets;

use crate::players::IgnisPlayers;

/// Render world, before the views' depth textures are made: every 3D camera's depth can
/// be sampled (the particles' soft edges and the splat's depth test read it).
pub fn sampleable_depth(mut cameras: Query<&mut Camera3d>) {
    for mut camera in &mut cameras {
        let usage = TextureUsages::from(camera.depth_texture_usages);
        if !usage.contains(TextureUsages::TEXTURE_BINDING) {
            camera.depth_texture_usages = (usage | TextureUsages::TEXTURE_BINDING).into();
        }
    }
}

/// Core3d, after the transparent pass: records and draws the players of this view's
/// target kind. The first view to record a player this frame runs its steps; a later one
/// first submits the work recorded so far (earlier views' cameras went through the queue,
/// which this view's record writes again), then records its own sort and splat.
pub fn draw_players(
    view: ViewQuery<(
        &ExtractedCamera,
        &ExtractedView,
        &ViewTarget,
        &ViewDepthStencilTexture,
        &Msaa,
    )>,
    mut players: ResMut<IgnisPlayers>,
    mut flush: FlushCommands,
    mut ctx: RenderContext,
) {
    let (camera, extracted, target, depth, msaa) = view.into_inner();
    let kind = (target.main_texture_format(), msaa.samples());
    let ours = |key: &crate::players::PlayerKey| (key.1, key.2) == kind;
    if (players.players.iter()).any(|(k, vp)| ours(k) && vp.recorded > 0) {
        flush.flush();
    }
    let Some(size) = camera.physical_viewport_size else {
        return;
    };
    let view_from_world = extracted.world_from_view.to_matrix().inverse();
    let ignis_camera = ignis::Camera::new(
        view_from_world.to_cols_array_2d(),
        extracted.clip_from_view.to_cols_array_2d(),
        (size.x, size.y),
    );
    let views = depth.attachment.depth_stencil_views();
    let sampled = views.depth_only_view().map(|v| &**v);
    let main = &**target.main_texture_view();
    let multisampled = target.sampled_main_texture_view().map(|v| &**v);
    let targets = HostTargets {
        color: multisampled.unwrap_or(main),
        resolve_target: multisampled.map(|_| main),
        depth: Some(&**views.attachment_view()),
    };
    let diagnostics = ctx.diagnostic_recorder();
    let diagnostics = diagnostics.as_deref();
    let encoder = ctx.command_encoder();
    let span = diagnostics.time_span(encoder, "ignis");
    for (key, vp) in players.players.iter_mut() {
        if !ours(key) {
            continue;
        }
        vp.recorded += 1;
        if let Err(e) = vp.player.record(encoder, &ignis_camera, sampled) {
            let message = e.to_string();
            if vp.last_error.as_ref() != Some(&message) {
                error!("ignis: {message}");
                vp.last_error = Some(message);
            }
        }
        vp.player.draw_to(encoder, &targets);
    }
    span.end(encoder);
}
