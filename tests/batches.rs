//! The runtime's batches as a host sees them: instances of one preset share their
//! batch's dispatches and draws. The commands a frame records (`Player::recorded_commands`)
//! for 1, 16, 17 and 100 torches on every draw path: one batch grows to hold them all
//! (the same commands whatever the count); with batches of at most 16, each further
//! batch adds the same step (17: two, 100: seven). The smoke's sort is one per batch, but
//! its bitonic network grows with the log² of the batch's particles: with smoke, the
//! draws are checked exactly and the dispatches within that growth; the additive
//! torch's commands are checked exactly.

// The runtime tests' host (this file uses part of it).
#[allow(dead_code)]
#[path = "runtime/host.rs"]
mod host;

use glam::{Mat4, vec3};
use host::Host;
use ignis::effect::{BlendMode, DrawPath, Effect};
use ignis::{CommandCounts, Player};

fn torch_on(path: DrawPath, smoke: bool) -> Effect {
    let path_ = format!("{}/presets/torch.ron", env!("CARGO_MANIFEST_DIR"));
    let mut effect = ignis::preset::load(path_.as_ref()).expect("shipped preset");
    if !smoke {
        effect
            .emitters
            .retain(|e| e.look.blend == BlendMode::Additive);
    }
    for e in &mut effect.emitters {
        // The splat takes additive layers only; the smoke stays on the billboards.
        if path != DrawPath::Splat || e.look.blend == BlendMode::Additive {
            e.look.draw_path = path;
        }
    }
    assert!(ignis::testing::sim::batch::batchable(&effect));
    effect
}

/// A frame's commands with `n` torches on a grid 0.3 m apart in batches of at most
/// `max` instances, after the same 30 frames of warm-up whatever `n` (the same steps),
/// and whether the frame shows fire.
fn frame_commands(host: &Host, effect: &Effect, n: u32, max: u32) -> (CommandCounts, bool) {
    let settings = ignis::PlayerSettings {
        max_batch_instances: max,
        ..host.settings()
    };
    let mut player = Player::new(&host.device, &host.queue, effect, settings).expect("player");
    for i in 0..n {
        let (x, z) = ((i % 10) as f32 * 0.3 - 1.35, -((i / 10) as f32) * 0.3);
        player
            .add_instance(Mat4::from_translation(vec3(x, 0.0, z)), i + 1)
            .expect("instance");
    }
    for _ in 0..30 {
        let mut enc = host.device.create_command_encoder(&Default::default());
        player.advance(1.0 / 60.0);
        player.record(&mut enc, &host.camera, None).expect("record");
        host.queue.submit([enc.finish()]);
    }
    player.advance(1.0 / 60.0);
    let frame = host.frame([0.0; 3], &[], &mut [&mut player], true);
    let lit = frame.rgba.iter().any(|p| p[0] > 0.05);
    (player.recorded_commands(), lit)
}

// One test per path: each plays 1, 16, 17 and 100 torches in one batch and 17 and 100
// in batches of 16, with and without smoke; the paths run side by side.
#[test]
fn instances_on_billboards_share_their_batch_dispatches_and_draws() {
    instances_share_their_batch_commands(DrawPath::Billboard);
}

#[test]
fn instances_on_tiles_share_their_batch_dispatches_and_draws() {
    instances_share_their_batch_commands(DrawPath::Tiles);
}

#[test]
fn instances_on_the_splat_share_their_batch_dispatches_and_draws() {
    instances_share_their_batch_commands(DrawPath::Splat);
}

/// 1, 16, 17 and 100 torches on `path` record the commands of one batch; in batches of
/// 16, 17 record two batches' and 100 seven's, each further batch the same step (with
/// smoke: the draws exactly, the dispatches within the sort's growth).
fn instances_share_their_batch_commands(path: DrawPath) {
    let host = Host::new(vec3(0.0, 1.5, 3.5), vec3(0.0, 0.8, -1.0));
    for smoke in [false, true] {
        let what = format!("{path:?}, smoke {smoke}");
        let effect = torch_on(path, smoke);
        let [one, sixteen, seventeen, hundred] =
            [1, 16, 17, 100].map(|n| commands(&host, &effect, n, 128));
        eprintln!(
            "{what}: 1, 16, 17, 100 torches in one batch record {one:?}, {sixteen:?}, {seventeen:?}, {hundred:?}"
        );
        assert!(one.dispatches > 0 && one.draws > 0, "{what}: {one:?}");
        assert_eq!(one, sixteen, "{what}: 16 instances in one batch");
        assert_eq!(
            one, seventeen,
            "{what}: 17 instances in one batch grown to 32"
        );
        let [two, seven] = [17, 100].map(|n| commands(&host, &effect, n, 16));
        eprintln!("{what}: 17, 100 torches in batches of 16 record {two:?}, {seven:?}");
        let per_batch = two - one;
        assert!(
            per_batch.dispatches > 0,
            "{what}: a second batch steps nowhere"
        );
        let five = seven - two;
        assert_eq!(five.draws, 5 * per_batch.draws, "{what}: draws per batch");
        if smoke {
            // One sort of 100 instances' smoke runs a longer network than one of 1 (and
            // each batch of 16 than the batch of 1 that ends the seven).
            assert_eq!(hundred.draws, one.draws, "{what}: draws of one batch");
            let growth = hundred.dispatches - one.dispatches;
            assert!(
                growth <= 24,
                "{what}: 100 in one batch {hundred:?}, 1 {one:?}"
            );
            let growth = 5 * per_batch.dispatches - five.dispatches;
            assert!(
                growth <= 8,
                "{what}: five batches {five:?}, the second {per_batch:?}"
            );
        } else {
            assert_eq!(hundred, one, "{what}: 100 instances in one batch");
            assert_eq!(
                five.dispatches,
                5 * per_batch.dispatches,
                "{what}: dispatches per batch"
            );
        }
    }
}

/// The commands of `n` torches of `effect` in batches of at most `max`, checked to draw.
fn commands(host: &Host, effect: &Effect, n: u32, max: u32) -> CommandCounts {
    let (c, lit) = frame_commands(host, effect, n, max);
    assert!(lit, "{n} torches in batches of {max}: no fire drawn");
    c
}

/// A batch's buffers double as instances come, at the record after an instance finds
/// them full: 1 and 16 torches are held by buffers for 16, 32 (added at once) by 32, 33
/// by 64, 100 by 128; with
/// batches of at most 16, 17 torches are two batches, each with buffers for 16.
#[test]
fn a_batchs_buffers_double_as_instances_come() {
    let host = Host::new(vec3(0.0, 1.5, 3.5), vec3(0.0, 0.8, -1.0));
    let effect = torch_on(DrawPath::Billboard, false);
    let record = |player: &mut Player| {
        let mut enc = host.device.create_command_encoder(&Default::default());
        player.advance(1.0 / 60.0);
        player.record(&mut enc, &host.camera, None).expect("record");
        host.queue.submit([enc.finish()]);
    };
    let mut player = host.player(&effect);
    let mut added = 0;
    for (n, slots) in [(1, 16), (16, 16), (32, 32), (33, 64), (100, 128)] {
        while added < n {
            player
                .add_instance(
                    Mat4::from_translation(vec3(added as f32 * 0.1, 0.0, 0.0)),
                    added + 1,
                )
                .expect("instance");
            added += 1;
        }
        if n > 1 {
            assert!(
                player.batch_buffer_slots()[0] <= slots,
                "{n} torches grew before the record"
            );
        }
        record(&mut player);
        assert_eq!(player.batch_buffer_slots(), [slots], "{n} torches");
    }
    let settings = ignis::PlayerSettings {
        max_batch_instances: 16,
        ..host.settings()
    };
    let mut player = Player::new(&host.device, &host.queue, &effect, settings).expect("player");
    for i in 0..17 {
        player
            .add_instance(Mat4::IDENTITY, i + 1)
            .expect("instance");
    }
    record(&mut player);
    assert_eq!(
        player.batch_buffer_slots(),
        [16, 16],
        "17 torches in batches of 16"
    );
}

/// The draws a frame reports are the record's plus the host's draw: more than a frame
/// recorded without drawing, and by no more than a handful (a count that wraps or
/// subtracts fails).
#[test]
fn a_frames_draws_are_counted_on_top_of_its_record() {
    let host = Host::new(vec3(0.0, 1.5, 3.5), vec3(0.0, 0.8, -1.0));
    let effect = torch_on(DrawPath::Billboard, false);
    let mut player: Player = host.player(&effect);
    player.add_instance(Mat4::IDENTITY, 1).expect("instance");
    let mut record_only = || {
        let mut enc = host.device.create_command_encoder(&Default::default());
        player.advance(1.0 / 60.0);
        player.record(&mut enc, &host.camera, None).expect("record");
        host.queue.submit([enc.finish()]);
        player.recorded_commands()
    };
    for _ in 0..30 {
        record_only();
    }
    let recorded = record_only();
    player.advance(1.0 / 60.0);
    host.frame([0.0; 3], &[], &mut [&mut player], true);
    let drawn = player.recorded_commands();
    assert!(
        drawn.draws > recorded.draws && drawn.draws <= recorded.draws + 16,
        "a record alone {recorded:?}, with the draw {drawn:?}"
    );
}

/// An edit that adds a trail (trails are not batched) moves every instance to a
/// simulation of its own, which draws its trail; the edit back batches them again: a
/// frame's commands are again those of the batch.
#[test]
fn an_edit_that_adds_a_trail_unbatches_the_instances_and_its_undo_batches_them() {
    let host = Host::new(vec3(0.0, 1.0, 4.0), vec3(0.0, 0.5, 0.0));
    let torch = torch_on(DrawPath::Billboard, false);
    let mut player: Player = host.player(&torch);
    let ids: Vec<_> = (0..4)
        .map(|i| {
            let at = Mat4::from_translation(vec3(i as f32 * 0.5 - 0.75, 0.0, 0.0));
            player.add_instance(at, i + 1).expect("instance")
        })
        .collect();
    let frames = |player: &mut Player, n: u32| {
        for _ in 0..n {
            let mut enc = host.device.create_command_encoder(&Default::default());
            player.advance(1.0 / 60.0);
            player.record(&mut enc, &host.camera, None).expect("record");
            host.queue.submit([enc.finish()]);
        }
        player.recorded_commands()
    };
    let batched = frames(&mut player, 10);
    let mut trailed = torch.clone();
    trailed.emitters[0].look.trail = Some(ignis::effect::Trail::default());
    assert!(!ignis::testing::sim::batch::batchable(&trailed));
    player.set_effect(&trailed).expect("the trail");
    let own = frames(&mut player, 10);
    assert!(
        own.dispatches > batched.dispatches,
        "{own:?} against {batched:?}"
    );
    for id in &ids {
        let ring = player.trail(*id, 0).expect("read");
        assert!(ring.is_some(), "instance {id:?} has its trail");
    }
    player.set_effect(&torch).expect("back");
    assert_eq!(frames(&mut player, 10), batched, "batched again");
    for id in &ids {
        assert!(player.trail(*id, 0).expect("read").is_none());
    }
}

/// Batches are drawn far to near by their instances' mean depth: in batches of at most
/// 16, 16 torches near the camera fill the first batch, a 17th far behind them starts
/// the second, whose draws come first.
#[test]
fn batches_are_drawn_far_to_near() {
    let host = Host::new(vec3(0.0, 1.0, 4.0), vec3(0.0, 0.5, 0.0));
    let torch = torch_on(DrawPath::Billboard, true);
    let settings = ignis::PlayerSettings {
        max_batch_instances: 16,
        ..host.settings()
    };
    let mut player = Player::new(&host.device, &host.queue, &torch, settings).expect("player");
    for i in 0..17 {
        let at = if i < 16 {
            vec3((i % 4) as f32 * 0.3 - 0.45, 0.0, 2.0 - (i / 4) as f32 * 0.1)
        } else {
            vec3(0.0, 0.0, -6.0)
        };
        player
            .add_instance(Mat4::from_translation(at), i + 1)
            .expect("instance");
    }
    let mut enc = host.device.create_command_encoder(&Default::default());
    player.advance(1.0 / 60.0);
    player.record(&mut enc, &host.camera, None).expect("record");
    host.queue.submit([enc.finish()]);
    let groups: Vec<(usize, u32)> = player
        .draw_items()
        .iter()
        .map(|d| (d.group, d.members))
        .collect();
    let first = groups.iter().find(|(g, _)| *g == 0).expect("a first group");
    let second = groups
        .iter()
        .find(|(g, _)| *g == 1)
        .expect("a second group");
    assert_eq!(
        (first.1, second.1),
        (1, 16),
        "the far batch first: {groups:?}"
    );
}
