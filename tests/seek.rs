//! Seeking: the state at time t is the state playing to t reaches. `Player::seek` replays
//! the frames from the start as fast as the GPU goes; these tests hold it to playing frame
//! by frame, bit for bit, for every shipped preset, forwards and backwards, and hold
//! `ignis render --start` to the frame a full render writes at that time.
// `ignis render` is the binary: the default `editor` feature.
#![cfg(feature = "editor")]

mod common;

use common::{gpu, run_ok};
use ignis::testing::headless::Headless;
use ignis::testing::shaders::ShaderLibrary;

const FPS: f64 = 60.0;

/// A headless run whose instance has a simulation of its own (as the editor's): the
/// player keeps seek snapshots for those.
fn unbatched(ctx: &ignis::testing::gpu::GpuContext, effect: ignis::Effect) -> Headless {
    let settings = ignis::PlayerSettings {
        batch_instances: false,
        ..ignis::testing::composite::Composite::player_settings()
    };
    Headless::with_settings(ctx, effect, ShaderLibrary::embedded(), settings).expect("headless")
}

/// Every emitter's particles of the headless instance, as bytes.
fn state(run: &Headless) -> Vec<Vec<u8>> {
    (0..run.effect().emitters.len())
        .map(|e| {
            let particles = run
                .player
                .particles(run.instance, e)
                .unwrap_or_else(|err| panic!("reading emitter {e}: {err}"));
            bytemuck::cast_slice(&particles).to_vec()
        })
        .collect()
}

/// For every shipped preset: the states at 1 s, 2 s and 3 s played frame by frame at
/// 60 fps, with snapshots every 0.75 s (a fixed-step seek starts from the latest one at or
/// before its target); then, from 3 s, seeks back to each — across snapshot boundaries
/// and between them — each bit-identical to the played state. Frame-delta presets
/// replay the same frame times.
#[test]
fn seeking_gives_the_played_state_bit_for_bit_for_every_shipped_preset() {
    let ctx = gpu();
    let presets = ignis::preset::list(std::path::Path::new("presets"));
    assert!(presets.len() >= 7, "the shipped presets: {presets:?}");
    for path in presets {
        let effect = ignis::preset::load(&path).expect("a shipped preset loads");
        let settings = ignis::PlayerSettings {
            asset_dir: path.parent().map(std::path::Path::to_path_buf),
            batch_instances: false,
            ..ignis::testing::composite::Composite::player_settings()
        };
        let mut run = Headless::with_settings(&ctx, effect, ShaderLibrary::embedded(), settings)
            .expect("headless");
        run.player.keep_seek_snapshots(0.75, 256 << 20);
        let mut played = Vec::new();
        for second in 1..=3 {
            for _ in 0..FPS as usize {
                run.advance(1.0 / FPS);
            }
            played.push((second, state(&run)));
        }
        let name = path.display();
        for (second, want) in played.iter().rev() {
            let frames = run.seek(f64::from(*second), 1.0 / FPS);
            assert_eq!(frames, *second as u64 * FPS as u64, "{name}");
            let got = state(&run);
            assert!(
                got.iter().zip(want).all(|(a, b)| a == b) && got.len() == want.len(),
                "{name}: the state after seeking to {second} s differs from the played one"
            );
            assert!(
                want.iter().any(|bytes| bytes.iter().any(|&b| b != 0)),
                "{name}: nothing alive at {second} s"
            );
        }
    }
}

/// `ignis render --start 2.0 --frames 1` writes the image the 121st frame of
/// `ignis render --frames 121` is (both at 60 fps), under the same frame number.
#[test]
fn render_start_writes_the_frame_a_full_render_writes_then() {
    let dir = tempfile::tempdir().expect("temp dir");
    let run = |out: &str, extra: &[&str]| {
        run_ok(
            std::process::Command::new(env!("CARGO_BIN_EXE_ignis"))
                .args(["render", "--size", "160x120", "--out"])
                .arg(dir.path().join(out))
                .args(extra),
        );
    };
    run("full", &["--frames", "121"]);
    run("start", &["--start", "2.0", "--frames", "1"]);
    let written: Vec<_> = std::fs::read_dir(dir.path().join("start"))
        .expect("the --start frames")
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(written, ["frame_0120.png"]);
    let a = std::fs::read(dir.path().join("full/frame_0120.png")).expect("frame 121");
    let b = std::fs::read(dir.path().join("start/frame_0120.png")).expect("--start frame");
    assert!(
        a == b,
        "--start 2.0 wrote a different image from the 121st frame"
    );
    let lit = image::load_from_memory(&b)
        .expect("a PNG")
        .to_rgba8()
        .pixels()
        .filter(|p| p[0] > 60)
        .count();
    assert!(lit > 100, "the frame shows the fire ({lit} lit pixels)");
}

/// With snapshots every 0.5 s (taken while playing), seeks start from the latest snapshot
/// at or before the target — between two of them, exactly on one, backwards — and still
/// give the played state bit for bit, for full, packed and tiny state alike.
#[test]
fn seeks_from_snapshots_give_the_played_state() {
    let ctx = gpu();
    for layout in ["full", "packed", "tiny"] {
        let mut effect = ignis::Effect::default_campfire();
        for e in &mut effect.emitters {
            e.packed_state = layout == "packed";
            e.tiny_state = layout == "tiny";
        }
        let mut run = unbatched(&ctx, effect);
        run.player.keep_seek_snapshots(0.5, 64 << 20);
        let mut played = Vec::new();
        for frame in 1..=150u32 {
            run.advance(1.0 / FPS);
            if frame % 45 == 0 || frame == 150 {
                played.push((f64::from(frame) / FPS, state(&run)));
            }
        }
        let (bytes, count) = run.player.seek_snapshot_bytes();
        assert!(
            count >= 4 && bytes > 0,
            "{layout}: {count} snapshots, {bytes} bytes"
        );
        for (t, want) in played.iter().rev() {
            run.seek(*t, 1.0 / FPS);
            assert!(
                state(&run) == *want,
                "{layout}: the state after seeking to {t:.2} s differs from the played one"
            );
            // From the latest snapshot at or before the target (one every 0.5 s).
            let start = run.player.last_seek_start_secs().expect("from a snapshot");
            assert!(
                start <= t + 1e-9 && t - start < 0.52,
                "{layout}: {t} s from {start} s"
            );
        }
        // Every seek restored a snapshot (a refused restore forgets them all and replays
        // from time 0, which reaches the same state).
        assert_eq!(
            run.player.seek_snapshot_bytes(),
            (bytes, count),
            "{layout}: the seeks kept the snapshots"
        );
        // Seeking forward past the last snapshot takes more as it goes, and agrees too.
        run.seek(0.0, 1.0 / FPS);
        for _ in 0..30 {
            run.advance(1.0 / FPS);
        }
        let half = state(&run);
        run.seek(3.0, 1.0 / FPS);
        run.seek(0.5, 1.0 / FPS);
        assert!(
            state(&run) == half,
            "{layout}: 0.5 s after a seek to 3 s and back"
        );
    }
}

/// The snapshots stay within their memory bound: when more would be needed, every other
/// one goes and the interval doubles.
#[test]
fn seek_snapshots_stay_within_their_memory_bound() {
    let ctx = gpu();
    let mut run = unbatched(&ctx, ignis::Effect::default_campfire());
    let bound = 2 << 20;
    run.player.keep_seek_snapshots(0.05, bound);
    for _ in 0..240 {
        run.advance(1.0 / FPS);
    }
    let (bytes, count) = run.player.seek_snapshot_bytes();
    assert!(
        bytes <= bound && count >= 2,
        "{count} snapshots, {bytes} bytes"
    );
    // Each snapshot holds both state buffers of every pool, and the events' scratch (a
    // word per parent slot and block, the spawn list's header): the bound counts them all.
    let states: u64 = run
        .player
        .effect()
        .emitters
        .iter()
        .map(|e| 2 * 32 * u64::from(e.capacity))
        .sum();
    assert!(
        bytes >= count as u64 * states && bytes < count as u64 * 2 * states,
        "{count} snapshots, {bytes} bytes: {states} bytes of state each"
    );
}

/// The snapshots' schedule as documented: one every `every_secs` of simulated time, none
/// for an interval of 0 or less; within a bound of exactly four snapshots' bytes, the
/// fifth drops every other one and the interval doubles — against that rule run over the
/// steps the clock took (frames of one step: the campfire's 1/120 s).
#[test]
fn seek_snapshots_follow_their_interval_and_thin_at_their_bound() {
    let ctx = gpu();
    let effect = ignis::Effect::default_campfire();
    let dt = f64::from(effect.time.step_secs);
    // Each frame's step and the snapshots kept after it, and their bytes at the end.
    let play = |every_secs: f64, bound: u64, frames: u32| {
        let mut run = unbatched(&ctx, effect.clone());
        run.player.keep_seek_snapshots(every_secs, bound);
        let kept: Vec<(u64, usize)> = (0..frames)
            .map(|_| {
                run.advance(dt);
                let secs = run.player.time_secs(run.instance).expect("time");
                (
                    (secs / dt).round() as u64,
                    run.player.seek_snapshot_bytes().1,
                )
            })
            .collect();
        (kept, run.player.seek_snapshot_bytes().0)
    };
    for every in [0.0, -1.0] {
        let (none, _) = play(every, u64::MAX, 30);
        assert!(
            none.iter().all(|&(_, n)| n == 0),
            "every {every} s: {none:?}"
        );
    }
    let every = (0.1 / dt).round() as u64;
    let (first, bytes) = play(0.1, u64::MAX, 40);
    let taken = counts(&first);
    assert_eq!(taken, schedule(&first, every, usize::MAX));
    let one = bytes / taken.last().map_or(1, |&n| n.max(1)) as u64;
    let (kept, _) = play(0.1, 4 * one, 150);
    let want = schedule(&kept, every, 4);
    assert_eq!(counts(&kept), want);
    let thinned = want.windows(2).filter(|w| w[1] < w[0]).count();
    assert!(thinned >= 2 && want.contains(&4), "{want:?}");
}

/// The snapshots kept after each frame.
fn counts(kept: &[(u64, usize)]) -> Vec<usize> {
    kept.iter().map(|&(_, n)| n).collect()
}

/// The documented rule over the steps after each frame: a snapshot at the first step at
/// least `every` after the last one; past `max` snapshots every other one goes (the
/// older of each pair) and the interval doubles. The snapshots kept after each frame.
fn schedule(kept: &[(u64, usize)], mut every: u64, max: usize) -> Vec<usize> {
    let mut list: Vec<u64> = Vec::new();
    kept.iter()
        .map(|&(step, _)| {
            if step >= list.last().copied().unwrap_or(0) + every && !list.contains(&step) {
                list.push(step);
                if list.len() > max {
                    list = list.iter().skip(1).step_by(2).copied().collect();
                    every *= 2;
                }
            }
            list.len()
        })
        .collect()
}

/// A frame-delta effect seeks by replaying its frames even while snapshots are kept
/// (they stand only for fixed steps): the thesis preset's state after 100 frames of
/// 1/45 s is what a seek to 100/45 s in frames of 1/45 s gives — a target between the
/// steps a snapshot would be taken at, so that no snapshot can stand for it.
#[test]
fn a_frame_delta_effect_seeks_by_replaying_its_frames_with_snapshots_kept() {
    let ctx = gpu();
    let effect = ignis::preset::load(std::path::Path::new("presets/thesis_2006.ron"))
        .expect("the thesis preset");
    assert_eq!(effect.time.mode, ignis::effect::TimeMode::FrameDelta);
    let mut run = unbatched(&ctx, effect);
    run.player.keep_seek_snapshots(0.25, 256 << 20);
    for _ in 0..100 {
        run.advance(1.0 / 45.0);
    }
    let want = state(&run);
    assert_eq!(run.seek(100.0 / 45.0, 1.0 / 45.0), 100);
    assert!(
        state(&run) == want,
        "the seek's state differs from the played one"
    );
}

/// A seek from a snapshot replays every step after it, in records of at most 32 steps
/// (here 40: two records), and says which snapshot it started from.
#[test]
fn a_seek_replays_every_step_after_its_snapshot() {
    let ctx = gpu();
    let effect = ignis::Effect::default_campfire();
    let dt = f64::from(effect.time.step_secs);
    let mut run = unbatched(&ctx, effect);
    run.player.keep_seek_snapshots(0.5, 256 << 20);
    for _ in 0..100 {
        run.advance(dt);
    }
    let want = state(&run);
    let (_, count) = run.player.seek_snapshot_bytes();
    assert_eq!(count, 1, "one snapshot, at 0.5 s");
    assert_eq!(run.seek(100.0 * dt, dt), 100);
    assert!(state(&run) == want, "about 60 steps restored, 40 replayed");
    let start = run.player.last_seek_start_secs();
    assert!(
        start.is_some_and(|s| (s - 0.5).abs() < 1.5 * dt),
        "{start:?}"
    );
    run.seek(0.25, dt);
    assert_eq!(
        run.player.last_seek_start_secs(),
        None,
        "before the first snapshot"
    );
}

/// A seek to a time or in frames that are not positive finite numbers replays nothing:
/// the clock goes back to 0, at once.
#[test]
fn a_seek_to_an_impossible_time_goes_back_to_the_start() {
    let ctx = gpu();
    let mut run = unbatched(&ctx, ignis::Effect::default_campfire());
    for _ in 0..10 {
        run.advance(1.0 / FPS);
    }
    for (secs, dt) in [
        (1.0, 0.0),
        (1.0, -1.0 / FPS),
        (f64::INFINITY, 1.0 / FPS),
        (f64::NAN, 1.0 / FPS),
        (-2.0, 1.0 / FPS),
    ] {
        assert_eq!(run.seek(secs, dt), 0, "seek({secs}, {dt})");
        assert_eq!(run.player.time_secs(run.instance), Some(0.0));
    }
}

/// A frame-delta effect's state depends on every frame's duration: replaying the frames
/// played (jittered here) reaches the played state bit for bit, at any point of them.
#[test]
fn replaying_the_played_frames_reaches_the_played_state_in_frame_delta_mode() {
    let ctx = gpu();
    let effect = ignis::preset::load(std::path::Path::new("presets/thesis_2006.ron"))
        .expect("the thesis preset");
    assert_eq!(effect.time.mode, ignis::effect::TimeMode::FrameDelta);
    let mut run = unbatched(&ctx, effect);
    let frames: Vec<f64> = (0..120)
        .map(|i| [1.0 / 60.0, 1.0 / 45.0, 1.0 / 90.0, 1.0 / 30.0][i % 4])
        .collect();
    let mut played = Vec::new();
    for (i, dt) in frames.iter().enumerate() {
        run.advance(*dt);
        if i == 59 || i == 119 {
            played.push((i + 1, state(&run)));
        }
    }
    for (n, want) in played.iter().rev() {
        run.player.replay(&frames[..*n]);
        assert!(state(&run) == *want, "after replaying {n} frames");
    }
    // Uniform frames instead reach another state: the durations matter.
    run.player.replay(&vec![1.0 / 60.0; 60]);
    assert!(
        state(&run) != played[0].1,
        "frame times must matter in frame-delta mode"
    );
}

/// An edit forgets the snapshots and takes none of the state simulated before it: a later
/// seek gives what playing the edited effect from the start gives. Seeking in frames of
/// one step lands on every step (the editor's step back).
#[test]
fn an_edit_forgets_the_snapshots_and_seeks_land_on_steps() {
    let ctx = gpu();
    let effect = ignis::Effect::default_campfire();
    let mut edited = effect.clone();
    edited.emitters[1].spawn_rate_per_sec = edited.emitters[1].spawn_rate_per_sec.scaled(1.5);
    let mut run = unbatched(&ctx, effect);
    run.player.keep_seek_snapshots(0.25, 64 << 20);
    for _ in 0..120 {
        run.advance(1.0 / FPS);
    }
    run.player.set_effect(&edited).expect("the edit");
    for _ in 0..60 {
        run.advance(1.0 / FPS);
    }
    run.seek(2.5, 1.0 / FPS);
    let mut fresh = unbatched(&ctx, edited);
    for _ in 0..150 {
        fresh.advance(1.0 / FPS);
    }
    assert!(state(&run) == state(&fresh), "a seek after an edit");

    let step = f64::from(run.effect().time.step_secs);
    for k in [1u32, 119, 120, 121] {
        run.seek(f64::from(k) * step, step);
        let t = run.player.time_secs(run.instance).expect("time");
        assert!((t - f64::from(k) * step).abs() < 1e-9, "step {k}: at {t} s");
    }
}

/// Moving an instance forgets the snapshots (they hold particles born at the old place);
/// setting the transform it already has keeps them. A seek back then replays from the
/// start at the new place.
#[test]
fn moving_an_instance_forgets_the_snapshots_and_standing_still_keeps_them() {
    let ctx = gpu();
    let effect = ignis::Effect::default_campfire();
    let moved = glam::Mat4::from_translation(glam::vec3(0.5, 0.0, 0.0));
    let mut run = unbatched(&ctx, effect.clone());
    run.player.keep_seek_snapshots(0.25, 64 << 20);
    for _ in 0..120 {
        run.advance(1.0 / FPS);
    }
    let kept = run.player.seek_snapshot_bytes().1;
    assert!(kept >= 4, "{kept} snapshots");
    let id = run.instance;
    let here = run.player.transform(id).expect("a transform");
    assert!(run.player.set_transform(id, here));
    assert_eq!(run.player.seek_snapshot_bytes().1, kept, "standing still");
    assert!(run.player.set_transform(id, moved));
    assert_eq!(run.player.seek_snapshot_bytes().1, 0, "moved");
    run.seek(1.0, 1.0 / FPS);
    let mut fresh = unbatched(&ctx, effect);
    assert!(fresh.player.set_transform(fresh.instance, moved));
    for _ in 0..60 {
        fresh.advance(1.0 / FPS);
    }
    assert!(state(&run) == state(&fresh), "a seek back after a move");
}

/// Plays `n` frames of 1/60 s through the editor's timeline (`editor::timeline::play`,
/// then the simulation) and returns the instance's clock after each.
fn timeline_frames(
    ctx: &ignis::testing::gpu::GpuContext,
    run: &mut Headless,
    playback: &mut ignis::testing::editor::state::Playback,
    n: u32,
) -> Vec<f64> {
    use ignis::testing::editor::panel::timeline::play;
    let mut times = Vec::new();
    for _ in 0..n {
        play(&mut run.player, run.instance, playback, false, 1.0 / FPS);
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        run.player.simulate(&mut enc);
        ctx.queue.submit([enc.finish()]);
        times.push(run.player.time_secs(run.instance).expect("time"));
    }
    times
}

/// The editor's timeline playback (`editor::timeline::play`, what its frame loop calls):
/// at 0.25× and 2× the effect's clock advances by a quarter and twice the frames' time; a
/// step while parked after a seek moves exactly one step; a loop region wraps back to its
/// start once the clock passes its end, and never runs past it by more than a frame.
#[test]
fn timeline_playback_speed_parked_steps_and_the_loop_region() {
    use ignis::testing::editor::state::Playback;
    let ctx = gpu();
    let effect = ignis::Effect::default_campfire();
    let step = f64::from(effect.time.step_secs);
    let mut run = unbatched(&ctx, effect);
    let id = run.instance;
    let frames = |run: &mut Headless, playback: &mut Playback, n: u32| {
        timeline_frames(&ctx, run, playback, n)
    };
    let now = |run: &Headless| run.player.time_secs(id).expect("time");
    let mut playback = Playback {
        speed: 0.25,
        ..Playback::default()
    };
    frames(&mut run, &mut playback, 60);
    assert!((now(&run) - 0.25).abs() <= step, "0.25×: {}", now(&run));
    assert!(!run.player.is_paused(), "a playing timeline's player runs");
    playback.speed = 2.0;
    frames(&mut run, &mut playback, 60);
    assert!((now(&run) - 2.25).abs() <= step, "2×: {}", now(&run));

    // A fixed-step effect keeps no frame times (only a frame-delta one replays them).
    assert!(
        playback.frame_times.is_empty(),
        "{:?}",
        playback.frame_times.len()
    );

    // Parked at 1 s by a seek, a step is one step; the view stays parked at that time
    // frame after frame (an edit then re-simulates to it).
    playback.seek_to = Some(1.0);
    frames(&mut run, &mut playback, 1);
    assert!(playback.is_paused && (now(&run) - 1.0).abs() <= 0.5 * step);
    assert!(
        run.player.is_paused(),
        "a parked timeline pauses its player"
    );
    frames(&mut run, &mut playback, 2);
    assert_eq!(playback.parked_at, Some(1.0), "still parked");
    let parked = now(&run);
    playback.step_requested = true;
    frames(&mut run, &mut playback, 1);
    assert!(
        (now(&run) - parked - step).abs() < 1e-9,
        "one step: {}",
        now(&run)
    );
    frames(&mut run, &mut playback, 10);
    assert!(
        (now(&run) - parked - step).abs() < 1e-9,
        "paused: {}",
        now(&run)
    );

    // Playing in the loop region 0.5–1.0 s: it wraps, and stays within it.
    playback.is_paused = false;
    playback.speed = 1.0;
    playback.loop_region = Some((0.5, 1.0));
    let times = frames(&mut run, &mut playback, 120);
    let wraps = times.windows(2).filter(|w| w[1] < w[0]).count();
    assert!(
        wraps >= 2,
        "{wraps} wraps in 2 s of a 0.5 s loop: {times:?}"
    );
    assert!(
        times
            .iter()
            .all(|t| *t >= 0.5 - step && *t < 1.0 + 1.0 / FPS + step),
        "{times:?}"
    );

    // A loop region of no length loops nothing: the clock runs on past it.
    playback.loop_region = Some((1.0, 1.0));
    frames(&mut run, &mut playback, 90);
    assert!(
        now(&run) > 1.2,
        "held at an empty loop region: {}",
        now(&run)
    );

    // An effect played at half speed: a seek to 1 s of its time lands there.
    let mut slow = ignis::Effect::default_campfire();
    slow.time.speed = 0.5;
    let mut run = unbatched(&ctx, slow);
    assert_eq!(run.instance, id, "the first instance of a player");
    let mut playback = Playback {
        seek_to: Some(1.0),
        ..Playback::default()
    };
    frames(&mut run, &mut playback, 1);
    assert!(
        (now(&run) - 1.0).abs() <= 0.5 * step,
        "a seek at half speed: {}",
        now(&run)
    );
}

/// A snapshot is restored only into the pools it was taken from: after a pool is rebuilt
/// (a new capacity) it is refused and nothing changes; into the same pools it puts the
/// state back.
#[test]
fn a_snapshot_of_a_rebuilt_pool_is_refused() {
    use ignis::testing::sim::GpuSim;
    let ctx = gpu();
    let effect = ignis::Effect::default_campfire();
    let dt = effect.time.step_secs;
    let mut sim = GpuSim::new(&ctx, ShaderLibrary::embedded(), &effect).expect("sim");
    sim.step(&effect, dt, 30).expect("step");
    let snapshot = |sim: &GpuSim| {
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        let s = sim.snapshot(&mut enc);
        ctx.queue.submit([enc.finish()]);
        s
    };
    let restore = |sim: &mut GpuSim, s| {
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        let done = sim.restore(&mut enc, s);
        ctx.queue.submit([enc.finish()]);
        done
    };
    let taken = snapshot(&sim);
    let at_snapshot = sim.read_particles(0).expect("read");
    sim.step(&effect, dt, 10).expect("step");
    assert!(restore(&mut sim, &taken), "the same pools");
    assert!(sim.read_particles(0).expect("read") == at_snapshot);

    let mut bigger = effect.clone();
    bigger.emitters[0].capacity *= 2;
    sim.sync(&bigger).expect("sync");
    sim.step(&bigger, dt, 5).expect("step");
    let before = sim.read_particles(0).expect("read");
    assert!(!restore(&mut sim, &taken), "restored into a rebuilt pool");
    assert!(
        sim.read_particles(0).expect("read") == before,
        "a refused restore changed the pool"
    );
}

/// A seek back past the tiny state's birth-table ring restores the entries its living
/// particles were born in: a tiny-state emitter living 1 s, played 12 s (1,440 steps: the
/// ring's 1,024 entries wrap), seeked back to 2.25 s from its snapshot at 2 s — whose
/// living particles' entries later steps overwrote — gives the played state.
#[test]
fn a_seek_back_past_the_birth_tables_wrap_restores_its_entries() {
    let ctx = gpu();
    let mut e = common::plain_emitter();
    e.tiny_state = true;
    e.capacity = 512;
    e.spawn_rate_per_sec = ignis::effect::Param::Constant(200.0);
    e.lifetime_secs = ignis::effect::Range::new(0.8, 1.0);
    e.speed_m_per_s = ignis::effect::Range::new(0.5, 1.0);
    e.spread_deg = 40.0;
    let mut run = unbatched(&ctx, common::bare_effect(e));
    run.player.keep_seek_snapshots(0.5, 64 << 20);
    let mut at = None;
    for frame in 1..=720u32 {
        run.advance(1.0 / FPS);
        if frame == 135 {
            at = Some(state(&run));
        }
    }
    let want = at.expect("the state at 2.25 s");
    run.seek(2.25, 1.0 / FPS);
    assert!(
        state(&run) == want,
        "the state after seeking back to 2.25 s differs from the played one"
    );
}
