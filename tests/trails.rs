//! Trails on a real adapter: the points a ribbon is drawn through are the particle's own
//! positions after the steps that recorded them (the ring read back, its entries chosen as
//! the vertex shader chooses them), a reused slot's ribbon holds only its new particle's
//! points, and the drawn ribbon lights the pixels between the particle and its tail,
//! narrowing from its width at the particle to its tail width (linearly, segment by
//! segment), and along a curve passes through its recorded points. A ribbon per parent
//! joins each parent's children in the order it spawned them, never two parents' lives
//! (nor a child to the new occupant of its predecessor's slot),
//! lights the pixels between them, and is each child's own width at its age. Ribbons lay
//! their sprite with its top on the motion's left, fade towards the ground by each point's
//! height, and take a colour inherited from a parent.

mod common;

use common::*;
use ignis::effect::*;
use ignis::testing::shaders::ShaderLibrary;
use ignis::testing::sim::GpuSim;
use ignis::testing::sim::trails::{Link, trail_indices};

const DT: f32 = 1.0 / 60.0;

/// The step numbers each point j ≥ 1 of a ribbon shows once `steps` steps have run: the
/// recording steps (multiples of `every`) before the last step, newest first.
fn point_steps(points: u32, every: u32, steps: u64) -> Vec<i64> {
    let before = steps as i64 - 2;
    let k = before - before.rem_euclid(i64::from(every));
    (1..i64::from(points))
        .map(|j| k - (j - 1) * i64::from(every))
        .collect()
}

/// The pixel tests' view of `effect`: fixed 1/60 s steps, seen side on from 3 m at 1 m
/// up (the x axis along the middle row), without bloom.
fn side_view(effect: &mut Effect) {
    effect.time.mode = TimeMode::FixedStep;
    effect.time.step_secs = DT;
    effect.camera = CameraHint {
        target_m: [0.0, 1.0, 0.0],
        distance_m: 3.0,
        yaw_deg: 0.0,
        pitch_deg: 0.0,
        fov_y_deg: 45.0,
    };
    effect.post.bloom = None;
}

/// The column of world x (at 1 m up, z = 0) in a `size` image of [`side_view`].
fn side_view_px(x: f32, (w, h): (u32, u32)) -> f32 {
    let px_per_m = (h as f32 / 2.0) / (3.0 * (22.5f32).to_radians().tan());
    w as f32 / 2.0 + x * px_per_m
}

/// The columns of `row` lit by the ribbon.
fn lit_pixels(image: &image::RgbaImage, row: u32) -> Vec<u32> {
    (0..image.width())
        .filter(|&x| image.get_pixel(x, row)[0] > 40)
        .collect()
}

#[test]
fn ribbon_points_are_the_recorded_positions_of_one_life() {
    let ctx = gpu();
    let (points, every) = (6u32, 2u32);
    let mut e = plain_emitter();
    // Eight slots, a particle every two steps living 12–15 steps: slots are reused often.
    e.capacity = 8;
    e.spawn_rate_per_sec = Param::Constant(30.0);
    e.lifetime_secs = Range::new(0.2, 0.25);
    e.speed_m_per_s = Range::new(1.0, 2.0);
    e.spread_deg = 60.0;
    e.forces.gravity_m_per_s2 = [0.0, -3.0, 0.0];
    e.look.trail = Some(Trail {
        points,
        // `every` steps of the effect's 1/120 s step between points.
        length_secs: (points * every) as f32 / 120.0,
        ..Trail::default()
    });
    let effect = bare_effect(e);
    effect.validate().expect("valid");
    let mut sim = GpuSim::new(&ctx, ShaderLibrary::embedded(), &effect).expect("sim");
    // Per slot: the current life's state after each step since its birth (step, pos_age).
    let mut lives: Vec<Vec<(i64, [f32; 4])>> = vec![Vec::new(); 8];
    let mut used = [false; 8];
    let (mut reused, mut checked) = (0, 0);
    for step in 0..90i64 {
        sim.step(&effect, DT, 1).expect("step");
        let particles = sim.read_particles(0).expect("read");
        for (slot, p) in particles.iter().enumerate() {
            let life = &mut lives[slot];
            if !p.is_alive() {
                life.clear();
                continue;
            }
            if life.last().is_some_and(|(_, q)| p.pos_age[3] < q[3]) {
                life.clear();
            }
            if life.is_empty() {
                // A birth; in a slot that held an earlier life: a reuse.
                reused += usize::from(used[slot]);
                used[slot] = true;
            }
            life.push((step, p.pos_age));
        }
        let ring = sim.read_trail(0).expect("read").expect("a trail");
        assert_eq!((ring.points, ring.every_steps), (points, every));
        let indices = trail_indices(points, every, step as u64 + 1);
        let steps = point_steps(points, every, step as u64 + 1);
        for (slot, life) in lives.iter().enumerate().filter(|(_, l)| !l.is_empty()) {
            let (birth, birth_point) = life[0];
            let now_age = life.last().map_or(0.0, |(_, q)| q[3]);
            for (&r, &k) in indices.iter().zip(&steps) {
                let got = ring.entry(slot, r as usize);
                // Before the birth: the birth point (the ring is refilled at birth).
                let want = if k <= birth {
                    birth_point
                } else {
                    life[(k - birth) as usize].1
                };
                assert_eq!(got, want, "step {step}, slot {slot}, point of step {k}");
                assert!(got[3] <= now_age, "a point older than the particle's life");
                checked += 1;
            }
        }
    }
    assert!(reused >= 10, "slots reused {reused} times");
    assert!(checked > 1000, "{checked} points checked");
}

const RING_PROBE: &str = r#"
#import "trail_ring.wgsl"
// Per case: the last step's number, the point j, the ring's points and its spacing.
@group(0) @binding(0) var<storage, read> cases: array<vec4<u32>>;
@group(0) @binding(1) var<storage, read_write> out: array<u32>;
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= arrayLength(&cases) {
        return;
    }
    let c = cases[id.x];
    out[id.x] = trail_point_entry(c.x, c.y, c.z, c.w);
}
"#;

/// The entry the draw reads for each point of a trail (`trail_point_entry`) is the one
/// `trail_indices` names, for rings of 2 to 16 points (powers of two and not), recorded
/// every 1 to 5 steps, after each of the first 200 steps (the ring filling, every phase of
/// the spacing, and the step before the first: the wrap of `last − 1`).
#[test]
fn the_draw_reads_the_ring_entries_the_recording_wrote() {
    let ctx = gpu();
    let mut cases: Vec<[u32; 4]> = Vec::new();
    let mut want: Vec<u32> = Vec::new();
    for points in [2u32, 3, 6, 9, 16] {
        for every in 1u32..=5 {
            for steps in 1u64..=200 {
                let last = (steps - 1) as u32;
                for (j, r) in (1..points).zip(trail_indices(points, every, steps)) {
                    cases.push([last, j, points, every]);
                    want.push(r);
                }
            }
        }
    }
    let n = cases.len() as u32;
    let bytes = run_probe(
        &ctx,
        RING_PROBE,
        bytemuck::cast_slice(&cases),
        u64::from(n) * 4,
        n.div_ceil(64),
    );
    let got: &[u32] = bytemuck::cast_slice(&bytes);
    for (i, (g, w)) in got.iter().zip(&want).enumerate() {
        assert_eq!(g, w, "case {:?}", cases[i]);
    }
}

/// The ribbon spans the same simulated time at any step: one particle flying with a
/// trail of 6 points over 0.1 s, stepped at 1/30 to 1/240 s for the same 0.5 s — the ages
/// recorded in its ring (read back from the GPU) run back 0.1 s from the newest point, in
/// `points` (or, on a step coarser than the spacing, one a step) entries.
#[test]
fn the_trail_spans_the_same_seconds_at_any_step() {
    let ctx = gpu();
    let mut e = plain_emitter();
    e.capacity = 4;
    burst_at_start(&mut e, 1);
    e.lifetime_secs = Range::new(5.0, 5.0);
    e.look.trail = Some(Trail {
        points: 6,
        length_secs: 0.1,
        ..Trail::default()
    });
    for (step, kept) in [
        (1.0 / 30.0, 3),
        (1.0 / 60.0, 6),
        (1.0 / 120.0, 6),
        (1.0 / 240.0, 6),
    ] {
        let mut effect = bare_effect(e.clone());
        effect.time.step_secs = step;
        let layout = e.look.trail.as_ref().expect("trail").layout(step);
        assert_eq!(layout.points, kept, "step {step}");
        assert!(
            (layout.span_secs(step) - 0.1).abs() < 1e-6,
            "step {step}: {layout:?}"
        );
        let mut sim = GpuSim::new(&ctx, ShaderLibrary::embedded(), &effect).expect("sim");
        let steps = (0.5 / step).round() as u32;
        sim.step(&effect, step, steps).expect("step");
        let ring = sim.read_trail(0).expect("read").expect("a trail");
        assert_eq!(ring.points, kept);
        let slot = (0..4)
            .find(|&s| ring.entry(s, 0)[3] > 0.0)
            .expect("the particle's ring");
        let ages: Vec<f32> = (0..kept as usize).map(|r| ring.entry(slot, r)[3]).collect();
        let newest = ages.iter().copied().fold(f32::MIN, f32::max);
        let oldest = ages.iter().copied().fold(f32::MAX, f32::min);
        // The entries are `every` steps apart: the span minus one spacing.
        let want = 0.1 - f64::from(layout.every) * f64::from(step);
        assert!(
            (f64::from(newest - oldest) - want).abs() < 1e-4,
            "step {step}: ages {ages:?}, span {} s, want {want}",
            newest - oldest
        );
    }
}

/// One particle flying straight across the view with a ribbon and no sprite: the lit
/// pixels run from the particle back to its oldest point, not beyond.
/// One particle born at x = −1, 1 m up, flying along +x at 1.2 m/s for 60 steps of
/// [`side_view`], drawn as a ribbon of `points` points `every` steps apart (no sprite),
/// `width` times its `size_m` wide at the particle and `tail_width` times that at its tail;
/// rendered at `size`.
fn straight_ribbon(
    (points, every): (u32, u32),
    (size_m, width, tail_width): (f32, f32, f32),
    size: (u32, u32),
) -> image::RgbaImage {
    let mut run = ribbon_run((points, every), (size_m, width, tail_width), |_| {});
    run.render(size).expect("render")
}

/// The played run of [`straight_ribbon`], its emitter changed by `edit` first.
fn ribbon_run(
    (points, every): (u32, u32),
    (size_m, width, tail_width): (f32, f32, f32),
    edit: impl FnOnce(&mut Emitter),
) -> ignis::testing::headless::Headless {
    let mut e = plain_emitter();
    e.capacity = 4;
    burst_at_start(&mut e, 1);
    e.lifetime_secs = Range::new(5.0, 5.0);
    e.transform.position_m = [-1.0, 1.0, 0.0];
    e.direction = [1.0, 0.0, 0.0];
    e.speed_m_per_s = Range::new(1.2, 1.2);
    e.look.size_m = Param::Constant(size_m);
    e.look.trail = Some(Trail {
        points,
        // `every` steps of side_view's 1/60 s step between points.
        length_secs: (points * every) as f32 * DT,
        width,
        tail_width,
        tail_opacity: 1.0,
        draw_sprite: false,
        ..Trail::default()
    });
    e.look.color_over_life = flat_color([1.0, 1.0, 1.0, 1.0]);
    e.look.intensity = 4.0;
    edit(&mut e);
    let mut effect = bare_effect(e);
    side_view(&mut effect);
    let ctx = gpu();
    let mut run = ignis::testing::headless::Headless::new(&ctx, effect, ShaderLibrary::embedded())
        .expect("headless");
    for _ in 0..RIBBON_FRAMES {
        run.advance(f64::from(DT));
    }
    run
}

/// The frames [`straight_ribbon`] plays.
const RIBBON_FRAMES: u32 = 60;

#[test]
fn the_ribbon_lights_the_pixels_between_the_particle_and_its_tail() {
    let (points, every) = (9u32, 2u32);
    let (w, h) = (320u32, 240u32);
    let image = straight_ribbon((points, every), (0.05, 1.0, 1.0), (w, h));
    // Born half way through the first step at x = −1, at 1.2 m/s: after step k it is at
    // −1 + 1.2 (k + ½) dt. The particle is drawn between its states after the last two
    // steps; the oldest point is the state after the oldest recording step shown.
    let to_px = |x: f32| side_view_px(x, (w, h));
    let after = |k: i64| -1.0 + 1.2 * (k as f32 + 0.5) * DT;
    let frames = RIBBON_FRAMES;
    let last_step = i64::from(frames) - 1;
    let (head_lo, head_hi) = (to_px(after(last_step - 1)), to_px(after(last_step)));
    let oldest_step = point_steps(points, every, u64::from(frames))
        .last()
        .copied()
        .expect("points");
    let tail = to_px(after(oldest_step));
    let row = h / 2;
    let lit = lit_pixels(&image, row);
    let (first, last) = (*lit.first().expect("lit pixels"), *lit.last().expect("lit"));
    assert!(
        (first as f32 - tail).abs() <= 2.0
            && (head_lo - 2.0..=head_hi + 2.0).contains(&(last as f32)),
        "lit {first}..={last}, ribbon from {tail:.1} to {head_lo:.1}..{head_hi:.1}"
    );
    assert_eq!(lit.len() as u32, last - first + 1, "one unbroken ribbon");
}

/// The ribbon is `width` × the particle's size wide at the particle and narrows linearly
/// along its points to `tail_width` of that at its tail: its lit height near the head is
/// that width (within what the sprite's soft edge leaves under the threshold), and near
/// the tail a quarter of it.
#[test]
fn the_ribbon_narrows_from_its_width_at_the_particle_to_its_tail_width() {
    let (w, h) = (640u32, 480u32);
    let (size_m, width, tail_width) = (0.2f32, 0.5f32, 0.25f32);
    let image = straight_ribbon((9, 2), (size_m, width, tail_width), (w, h));
    let lit = lit_pixels(&image, h / 2);
    let (first, last) = (*lit.first().expect("lit pixels"), *lit.last().expect("lit"));
    let height = |x: u32| (0..h).filter(|&y| image.get_pixel(x, y)[0] > 40).count() as f32;
    let px_per_m = side_view_px(1.0, (w, h)) - side_view_px(0.0, (w, h));
    let head_px = size_m * width * px_per_m;
    let span = (last - first) as f32;
    // A tenth of the ribbon in from each end: the width there, linear along the ribbon's
    // evenly spaced points (the first segment, to the particle, is shorter: a little slack).
    let near_head = height(last - (span * 0.1) as u32);
    let near_tail = height(first + (span * 0.1) as u32);
    let want_head = head_px * (1.0 - 0.1 * (1.0 - tail_width));
    let want_tail = head_px * (tail_width + 0.1 * (1.0 - tail_width));
    assert!(
        (0.6 * want_head..=want_head + 2.0).contains(&near_head),
        "near the particle {near_head} px high, the ribbon {want_head:.1}"
    );
    let ratio = near_tail / near_head;
    let want = want_tail / want_head;
    assert!(
        (ratio - want).abs() < 0.12,
        "tail over head {ratio:.2} ({near_tail} / {near_head} px), want {want:.2}"
    );
}

/// A ribbon along a curve is drawn through the points its ring recorded, each read where
/// the vertex shader reads it, and not across the curve: every shown point's pixel is lit,
/// the point one recording before the oldest shown is not, and neither is the middle of
/// the chord from the particle to its oldest point.
#[test]
fn a_curved_ribbon_passes_through_its_recorded_points() {
    let (points, every) = (9u32, 2u32);
    let mut run = ribbon_run((points, every), (0.05, 1.0, 1.0), |e| {
        // Thrown up and to the right, back at 1 m up after the run's 1 s: the ribbon's
        // 16 steps arc about 0.09 m off its chord.
        e.direction = [0.4, 0.917, 0.0];
        e.speed_m_per_s = Range::new(5.45, 5.45);
        e.forces.gravity_m_per_s2 = [0.0, -10.0, 0.0];
    });
    let (w, h) = (640u32, 480u32);
    let image = run.render((w, h)).expect("render");
    let ring = run
        .player
        .trail(run.instance, 0)
        .expect("read")
        .expect("a trail");
    let particles = run.player.particles(run.instance, 0).expect("read");
    let slot = particles
        .iter()
        .position(|p| p.is_alive())
        .expect("the particle");
    let world = run.player.particle_motion(run.instance).expect("read")[0].0;
    // The ring holds simulation-space positions: the particle's own gives the offset.
    let offset = world - glam::Vec3::from_slice(&particles[slot].pos_age[..3]);
    let px_per_m = side_view_px(1.0, (w, h)) - side_view_px(0.0, (w, h));
    let to_px = |p: glam::Vec3| {
        let q = p + offset;
        (
            side_view_px(q.x, (w, h)),
            h as f32 / 2.0 - (q.y - 1.0) * px_per_m,
        )
    };
    let lit_near = |(x, y): (f32, f32)| {
        (-1..=1).any(|dy: i32| {
            (-1..=1).any(|dx: i32| {
                let (px, py) = (x.round() as i32 + dx, y.round() as i32 + dy);
                px >= 0
                    && py >= 0
                    && (px as u32) < w
                    && (py as u32) < h
                    && image.get_pixel(px as u32, py as u32)[0] > 40
            })
        })
    };
    let entry = |r: u32| glam::Vec3::from_slice(&ring.entry(slot, r as usize)[..3]);
    let shown = trail_indices(points, every, u64::from(RIBBON_FRAMES));
    for (j, &r) in shown.iter().enumerate() {
        let at = to_px(entry(r));
        assert!(
            lit_near(at),
            "point {} (entry {r}) at {at:?} is dark",
            j + 1
        );
    }
    let oldest = to_px(entry(*shown.last().expect("points")));
    let head = to_px(world - offset);
    let chord = ((head.0 + oldest.0) / 2.0, (head.1 + oldest.1) / 2.0);
    assert!(!lit_near(chord), "the chord's middle {chord:?} is lit");
    // The entry before the oldest shown (the ring's next one back) lies beyond the tail.
    let before = (shown.last().copied().expect("points") + points - 1) % points;
    let beyond = to_px(entry(before));
    assert!(
        !lit_near(beyond),
        "the entry before the oldest, at {beyond:?}, is lit"
    );
}

/// A trail whose ring cannot fit one storage binding is refused with a message that names
/// the emitter and the fix (and nothing is half-built: the simulation is not created).
#[test]
fn a_trail_too_large_for_the_device_is_a_clear_error() {
    let ctx = gpu();
    let limit = ctx.device.limits().max_storage_buffer_binding_size;
    let mut e = plain_emitter();
    e.name = "long tails".into();
    // The state fits; 64 points of 16 bytes per slot do not.
    e.capacity = (limit / 1024 + 1024).min(u64::from(u32::MAX)) as u32;
    e.spawn_rate_per_sec = Param::Constant(0.0);
    e.look.trail = Some(Trail {
        points: 64,
        // A point every 1/120 s step: all 64 kept.
        length_secs: 64.0 / 120.0,
        ..Trail::default()
    });
    let effect = bare_effect(e);
    let err = match GpuSim::new(&ctx, ShaderLibrary::embedded(), &effect) {
        Ok(_) => panic!("a ring over the binding limit was accepted"),
        Err(err) => err.to_string(),
    };
    assert!(
        err.contains("long tails") && err.contains("fewer trail points"),
        "{err}"
    );
}

/// Parents flying straight out of the origin (each on a ray of its own) that leave still
/// children over their lives, drawn as a ribbon per parent.
fn ribbon_effect() -> Effect {
    ribbon_effect_at(30.0)
}

/// [`ribbon_effect`] with children spawned at `rate_per_sec` over each parent's life.
fn ribbon_effect_at(rate_per_sec: f32) -> Effect {
    let parent = Emitter {
        name: "parent".into(),
        capacity: 6,
        spawn_rate_per_sec: Param::Constant(8.0),
        lifetime_secs: Range::new(0.5, 0.5),
        speed_m_per_s: Range::new(2.0, 2.0),
        spread_deg: 90.0,
        events: vec![Event {
            trigger: Trigger::OverLife,
            emitter: "ribbon".into(),
            rate_per_sec,
            inherit_velocity: 0.0,
            ..Event::default()
        }],
        ..plain_emitter()
    };
    let mut ribbon = Emitter {
        name: "ribbon".into(),
        capacity: 128,
        lifetime_secs: Range::new(0.7, 0.7),
        ..plain_emitter()
    };
    ribbon.look.trail = Some(Trail {
        mode: TrailMode::PerParent,
        ..Trail::default()
    });
    let mut effect = bare_effect(parent);
    effect.emitters.push(ribbon);
    effect.validate().expect("valid");
    effect
}

/// The segments a ribbon per parent draws (read back: links, and the children's states)
/// join, on every step, two children of one parent life spawned one after the other —
/// children lie on their parent's ray, ordered by their distance from the origin — and
/// each parent's living children form one unbroken chain, while parent and child slots
/// are reused many times.
#[test]
fn a_ribbon_per_parent_joins_each_parents_children_in_order() {
    joins_children_in_order(ribbon_effect(), 128);
}

/// The same with several children per parent per step (360 a second at 120 steps a
/// second: three each step), in a pool four times as large.
#[test]
fn a_ribbon_per_parent_joins_several_children_a_step_in_spawn_order() {
    let mut effect = ribbon_effect_at(360.0);
    effect.emitters[1].capacity = 512;
    joins_children_in_order(effect, 512);
}

/// The same with the children's cap binding over a parent pool of two of the scan's
/// blocks (1,100 parents, 1,024 slots a block): each step's allowance runs out in the
/// first block, so the second, where parents are born, never lists a child — a parent
/// born there must still forget its slot's last life's child.
#[test]
fn a_capped_ribbon_per_parent_forgets_the_last_life_past_the_allowance() {
    let mut effect = ribbon_effect_at(12.0);
    let parent = &mut effect.emitters[0];
    parent.capacity = 1100;
    parent.spawn_rate_per_sec = Param::Constant(2200.0);
    parent.events[0].max_per_sec = 7200.0;
    effect.emitters[1].capacity = 8192;
    effect.validate().expect("valid");
    joins_children_in_order(effect, 8192);
}

/// The same with the cap binding inside one parent's children of a step: six parents ask
/// six children a step each, the cap allows fifteen, so the parent the allowance runs out
/// in lists only some of its children and links only those (its last listed child is the
/// one its next step's first joins). The children live 0.71 s, between two steps: at a
/// life of a whole number of steps, the last bit of each child's sampled life decides in
/// which of two steps it dies, and one step's children would not die together.
#[test]
fn a_capped_ribbon_per_parent_links_only_the_children_listed() {
    let mut effect = ribbon_effect_at(360.0);
    effect.emitters[0].events[0].max_per_sec = 900.0;
    effect.emitters[1].capacity = 1024;
    effect.emitters[1].lifetime_secs = Range::new(0.71, 0.71);
    effect.validate().expect("valid");
    joins_children_in_order(effect, 1024);
}

fn joins_children_in_order(effect: Effect, capacity: usize) {
    let ctx = gpu();
    let mut sim = GpuSim::new(&ctx, ShaderLibrary::embedded(), &effect).expect("sim");
    let (mut segments, mut rays_seen, mut births) = (0usize, 0usize, 0usize);
    let mut stamps = vec![0u32; capacity];
    for step in 0..180 {
        sim.step(&effect, DT, 1).expect("step");
        let children = sim.read_particles(1).expect("read");
        let ring = sim.read_trail(1).expect("read").expect("a ring");
        assert_eq!(ring.points, 1);
        let links: Vec<Link> = ring.entries.iter().map(|e| Link::from_entry(*e)).collect();
        let alive: Vec<usize> = (0..children.len())
            .filter(|&s| children[s].is_alive())
            .collect();
        for &s in &alive {
            births += usize::from(links[s].stamp != stamps[s]);
            stamps[s] = links[s].stamp;
        }
        // Children by ray (their parent's direction, to 1e-4 rad: a thousand parents' rays
        // seldom come closer), nearest the origin (oldest) first.
        let dir = |s: usize| {
            glam::Vec3::from_slice(&children[s].pos_age[..3])
                .as_dvec3()
                .normalize()
        };
        let mut rays: Vec<Vec<usize>> = Vec::new();
        for &s in &alive {
            match rays.iter_mut().find(|r| dir(r[0]).dot(dir(s)) > 1.0 - 5e-9) {
                Some(r) => r.push(s),
                None => rays.push(vec![s]),
            }
        }
        for ray in &mut rays {
            ray.sort_by(|&a, &b| {
                children[a].pos_age[3]
                    .total_cmp(&children[b].pos_age[3])
                    .reverse()
            });
            spawn_order_within_steps(ray, &children, capacity);
            // Each child but the oldest is joined to the one before it on its ray.
            for pair in ray.windows(2) {
                let got = links[pair[1]].drawn_prev(&links);
                assert_eq!(
                    got,
                    Some(pair[0] as u32),
                    "step {step}: {pair:?} not joined"
                );
            }
            // The oldest living child of a life has no drawn segment: its predecessor is
            // dead (or none), never another life's child.
            let first = links[ray[0]].drawn_prev(&links);
            assert!(
                first.is_none_or(|p| !children[p as usize].is_alive()),
                "step {step}: the oldest child of a ray joined to a living {first:?}"
            );
            segments += ray.len() - 1;
        }
        rays_seen += rays.len();
    }
    assert!(
        rays_seen > 500 && segments > 5000,
        "{rays_seen} rays, {segments} segments"
    );
    // 180 steps of about 120 children a second in 128 slots: every slot used a few times.
    assert!(births > 300, "{births} children born");
}

/// Orders each run of `ray` (sorted oldest first) born in one step — same age, same
/// place — as they were spawned: one parent's children of a step take consecutive slots
/// of the ring (wrapping at `capacity`), from the run's first free slot on.
fn spawn_order_within_steps(
    ray: &mut [usize],
    children: &[ignis::testing::gpu::types::Particle],
    capacity: usize,
) {
    let mut start = 0;
    while start < ray.len() {
        let age = children[ray[start]].pos_age[3];
        let len = ray[start..]
            .iter()
            .take_while(|&&s| children[s].pos_age[3] == age)
            .count();
        let run = &mut ray[start..start + len];
        let first = run
            .iter()
            .copied()
            .find(|&s| !run.contains(&((s + capacity - 1) % capacity)))
            .unwrap_or(run[0]);
        run.sort_by_key(|&s| (s + capacity - first) % capacity);
        start += len;
    }
}

/// A parent born at x = −1, 1 m up, flying along +x at 4 m/s for `parent_life` seconds,
/// spawning 5 still children a second (one at each 0.2 s of its age), each living
/// `child_life`; the children drawn as a ribbon per parent (no sprites) of `size_m` ×
/// `width`, narrowing to `tail_width` over a child's life; played 60 steps of
/// [`side_view`], the effect changed by `edit` first.
fn still_children_ribbon(
    (parent_life, child_life): (f32, f32),
    (size_m, width, tail_width): (f32, f32, f32),
    edit: impl FnOnce(&mut Effect),
) -> ignis::testing::headless::Headless {
    let ctx = gpu();
    let mut effect = ribbon_effect();
    let parent = &mut effect.emitters[0];
    parent.capacity = 1;
    burst_at_start(parent, 1);
    parent.lifetime_secs = Range::new(parent_life, parent_life);
    parent.transform.position_m = [-1.0, 1.0, 0.0];
    parent.direction = [1.0, 0.0, 0.0];
    parent.spread_deg = 0.0;
    parent.speed_m_per_s = Range::new(4.0, 4.0);
    parent.events[0].rate_per_sec = 5.0;
    let ribbon = &mut effect.emitters[1];
    ribbon.transform.position_m = [-1.0, 1.0, 0.0];
    ribbon.lifetime_secs = Range::new(child_life, child_life);
    ribbon.look.size_m = Param::Constant(size_m);
    ribbon.look.color_over_life = flat_color([1.0, 1.0, 1.0, 1.0]);
    ribbon.look.intensity = 4.0;
    ribbon.look.trail = Some(Trail {
        mode: TrailMode::PerParent,
        width,
        tail_width,
        tail_opacity: 1.0,
        draw_sprite: false,
        ..Trail::default()
    });
    side_view(&mut effect);
    edit(&mut effect);
    effect.validate().expect("valid");
    let mut run = ignis::testing::headless::Headless::new(&ctx, effect, ShaderLibrary::embedded())
        .expect("headless");
    for _ in 0..60 {
        run.advance(f64::from(DT));
    }
    run
}

/// Two children of one parent, still and side by side across the view: the ribbon per
/// parent lights the row between them and nothing beyond (no sprites drawn).
#[test]
fn a_ribbon_per_parent_lights_the_pixels_between_the_children() {
    let mut run = still_children_ribbon((0.45, 5.0), (0.05, 1.0, 1.0), |_| {});
    // Two children (5 a second over the parent's 0.45 s), where the parent was at ages
    // 0.2 and 0.4 (the end of the steps that crossed them): x ≈ −0.2 and 0.6.
    let mut xs: Vec<f32> = run
        .player
        .particle_motion(run.instance)
        .expect("read")
        .iter()
        .map(|(p, _)| p.x)
        .collect();
    xs.sort_by(f32::total_cmp);
    assert!(
        xs.len() == 2 && (xs[0] + 0.2).abs() < 0.1 && (xs[1] - 0.6).abs() < 0.1,
        "two children near x = −0.2 and 0.6: {xs:?}"
    );
    let (w, h) = (320u32, 240u32);
    let image = run.render((w, h)).expect("render");
    let to_px = |x: f32| side_view_px(x, (w, h));
    let (a, b) = (to_px(xs[0]), to_px(xs[1]));
    let row = h / 2;
    let lit = lit_pixels(&image, row);
    let (first, last) = (*lit.first().expect("lit pixels"), *lit.last().expect("lit"));
    assert!(
        (first as f32 - a).abs() <= 2.0 && (last as f32 - b).abs() <= 2.0,
        "lit {first}..={last}, children at {a:.1} and {b:.1}"
    );
    assert_eq!(lit.len() as u32, last - first + 1, "one unbroken ribbon");
    let lit_rows = (0..h)
        .filter(|&y| image.get_pixel(((a + b) / 2.0) as u32, y)[0] > 40)
        .count();
    assert!(lit_rows <= 4, "a thin ribbon: {lit_rows} rows lit");
}

/// The width tapers linearly over the ribbon's points, segment by segment, u = (segment +
/// fraction) / segments: with three points (two segments) narrowing to 0.4, the lit
/// height a quarter and three quarters into each segment is the width there, relative to
/// the height a quarter into the first.
#[test]
fn the_ribbon_narrows_linearly_segment_by_segment() {
    let (w, h) = (640u32, 480u32);
    let (points, every) = (3u32, 4u32);
    let tail_width = 0.4f32;
    // Born at x = −3.5 at 4 m/s: the points 0.27 m apart, the particle 0.17 m on.
    let mut run = ribbon_run((points, every), (0.15, 1.0, tail_width), |e| {
        e.transform.position_m = [-3.5, 1.0, 0.0];
        e.speed_m_per_s = Range::new(4.0, 4.0);
    });
    let image = run.render((w, h)).expect("render");
    let after = |k: i64| side_view_px(-3.5 + 4.0 * (k as f32 + 0.5) * DT, (w, h));
    let last = i64::from(RIBBON_FRAMES) - 1;
    // The particle as drawn (between its last two states), then its ring's points.
    let mut knots = vec![(after(last - 1) + after(last)) / 2.0];
    knots.extend(
        point_steps(points, every, u64::from(RIBBON_FRAMES))
            .into_iter()
            .map(after),
    );
    let height = |x: f32| {
        (0..h)
            .filter(|&y| image.get_pixel(x.round() as u32, y)[0] > 40)
            .count() as f32
    };
    let width_at = |u: f32| 1.0 - (1.0 - tail_width) * u;
    let at = |seg: usize, f: f32| knots[seg] + f * (knots[seg + 1] - knots[seg]);
    let reference = height(at(0, 0.25));
    assert!(
        reference > 10.0,
        "the ribbon is {reference} px high near the particle"
    );
    for seg in 0..2 {
        for f in [0.25f32, 0.75] {
            let u = (seg as f32 + f) / 2.0;
            let want = reference * width_at(u) / width_at(0.125);
            let got = height(at(seg, f));
            assert!(
                (got - want).abs() <= 0.1 * want + 1.5,
                "segment {seg} at {f}: {got} px high, the taper gives {want:.1} (knots {knots:?})"
            );
        }
    }
}

/// A ribbon per parent is each child's own width at its end (its size × the width,
/// tapering to the tail width over its life): three still children of one parent, aged
/// 0.8, 0.6 and 0.4 of their lives, light heights in proportion to those widths next to
/// each child, along both segments.
#[test]
fn a_ribbon_per_parent_is_each_childs_width_at_its_age() {
    let (w, h) = (640u32, 480u32);
    let tail_width = 0.2f32;
    let mut run = still_children_ribbon((0.65, 1.0), (0.1, 2.0, tail_width), |_| {});
    // (world x, age over life) of each child (the parent has died).
    let ages = run.player.particles(run.instance, 1).expect("read");
    let ages = ages.iter().filter(|p| p.is_alive());
    let places = run.player.particle_motion(run.instance).expect("read");
    let mut children: Vec<(f32, f32)> = places
        .iter()
        .zip(ages)
        .map(|((x, _), p)| (x.x, p.pos_age[3] / p.vel_life[3]))
        .collect();
    children.sort_by(|a, b| a.0.total_cmp(&b.0));
    assert_eq!(children.len(), 3, "three children: {children:?}");
    let image = run.render((w, h)).expect("render");
    let height = |x: f32| {
        (0..h)
            .filter(|&y| image.get_pixel(x.round() as u32, y)[0] > 40)
            .count() as f32
    };
    let width = |t: f32| 1.0 - (1.0 - tail_width) * t;
    let px = |i: usize| side_view_px(children[i].0, (w, h));
    // Beside each child, inside the segments that end there.
    let newest = height(px(2) - 4.0);
    assert!(newest > 10.0, "the newest child's end is {newest} px high");
    for (i, x) in [(0, px(0) + 4.0), (1, px(1) - 4.0), (1, px(1) + 4.0)] {
        let want = newest * width(children[i].1) / width(children[2].1);
        let got = height(x);
        assert!(
            (got - want).abs() <= 0.1 * want + 1.5,
            "beside child {i} (aged {:.2} of its life): {got} px high, want {want:.1}",
            children[i].1
        );
    }
}

/// Ribbons lay their sprite's middle column across the motion with its top on the
/// motion's left, as streaks do: moving right across the view, the flame wisp's bright
/// base is below the middle, for a trail and for a ribbon per parent (dim enough not to
/// saturate).
#[test]
fn ribbons_lay_their_sprite_with_its_top_on_the_motions_left() {
    let wisp = |e: &mut Emitter| {
        e.look.sprite = Sprite::FlameWisp;
        e.look.intensity = 0.25;
    };
    let mut trail = ribbon_run((9, 2), (0.3, 1.0, 1.0), wisp);
    // The motion runs along the middle row, y = 120.
    let (_, y) = light_centroid(&trail.render((320, 240)).expect("render"));
    assert!(y > 121.0, "a trail's light is centred at y = {y} px (down)");
    let mut ribbon = still_children_ribbon((0.45, 5.0), (0.3, 1.0, 1.0), |e| {
        wisp(&mut e.emitters[1]);
    });
    let (_, y) = light_centroid(&ribbon.render((320, 240)).expect("render"));
    assert!(
        y > 121.0,
        "a ribbon per parent's light is centred at y = {y} px"
    );
}

/// A child's trail takes the colour its parent hands it: white children of an orange
/// parent (1, 0.5, 0.25) with `inherit_color` draw orange trails, red over green over blue.
#[test]
fn an_inherited_colour_tints_a_childs_trail() {
    let mut effect = ribbon_effect();
    let parent = &mut effect.emitters[0];
    parent.look.color_over_life = flat_color([1.0, 0.5, 0.25, 1.0]);
    parent.look.size_m = Param::Constant(0.001);
    parent.events[0].inherit_color = true;
    let child = &mut effect.emitters[1];
    child.speed_m_per_s = Range::new(1.5, 1.5);
    child.look.color_over_life = flat_color([1.0, 1.0, 1.0, 1.0]);
    child.look.trail = Some(Trail {
        points: 6,
        length_secs: 0.1,
        draw_sprite: false,
        ..Trail::default()
    });
    let mut run = side_view_run(effect);
    for _ in 0..30 {
        run.advance(f64::from(DT));
    }
    let image = run.render((320, 240)).expect("render");
    let sum = |c: usize| image.pixels().map(|p| f64::from(p[c])).sum::<f64>();
    let (r, g, b) = (sum(0), sum(1), sum(2));
    assert!(
        r > 1000.0 && g < 0.85 * r && b < 0.85 * g,
        "the trails' light: R {r}, G {g}, B {b}"
    );
}

/// The light of [`side_view`]'s image `img` within 6 pixels of world point (x, y) (z = 0).
fn light_near(img: &image::RgbaImage, (x, y): (f32, f32)) -> f64 {
    let (w, h) = img.dimensions();
    let px_per_m = side_view_px(1.0, (w, h)) - side_view_px(0.0, (w, h));
    let (cx, cy) = (
        side_view_px(x, (w, h)),
        h as f32 / 2.0 - (y - 1.0) * px_per_m,
    );
    let mut sum = 0.0;
    for (px, py, p) in img.enumerate_pixels() {
        if (px as f32 + 0.5 - cx).abs() <= 6.0 && (py as f32 + 0.5 - cy).abs() <= 6.0 {
            sum += f64::from(p[0]);
        }
    }
    sum
}

/// A ribbon fades towards the ground by the height of each of its points (over a 2 m
/// soft ground at y = 0), not by its emitter's: a trail running down at 45° is dimmer
/// at the particle than at its tail, and so is a ribbon per parent between children
/// dropped along the same slope.
#[test]
fn ribbons_fade_towards_the_ground_by_the_height_of_each_point() {
    let ground = |e: &mut Emitter| {
        e.collisions.ground = Some(GroundPlane {
            height_m: 0.0,
            kill_on_contact: false,
        });
        e.look.soft_ground_m = 2.0;
        e.look.intensity = 0.5;
    };
    let down = [1.0, -1.0, 0.0];
    // From (−3, 3.5) at 4 m/s for a second: the particle near (−0.17, 0.67), its tail
    // 16 steps back near (−0.92, 1.42).
    let mut trail = ribbon_run((9, 2), (0.1, 1.0, 1.0), |e| {
        e.transform.position_m = [-3.0, 3.5, 0.0];
        e.direction = down;
        e.speed_m_per_s = Range::new(4.0, 4.0);
        ground(e);
    });
    let img = trail.render((320, 240)).expect("render");
    let (head, tail) = (light_near(&img, (-0.3, 0.8)), light_near(&img, (-0.8, 1.3)));
    assert!(
        head < 0.9 * tail,
        "a trail's light near its head {head}, near its tail {tail}"
    );
    // Children 0.2 s apart along the parent's slope, from (−1, 2): y ≈ 1.43, 0.87, 0.30.
    let mut ribbon = still_children_ribbon((0.65, 5.0), (0.1, 1.0, 1.0), |e| {
        e.emitters[0].transform.position_m = [-1.0, 2.0, 0.0];
        e.emitters[0].direction = down;
        ground(&mut e.emitters[1]);
    });
    let img = ribbon.render((320, 240)).expect("render");
    let s = 0.8f32 / 2f32.sqrt();
    let (high, low) = (
        light_near(&img, (-1.0 + 1.5 * s, 2.0 - 1.5 * s)),
        light_near(&img, (-1.0 + 2.5 * s, 2.0 - 2.5 * s)),
    );
    assert!(
        low < 0.75 * high,
        "a ribbon's light near its lower child {low}, its higher {high}"
    );
}

/// A ribbon per parent joins a child only to its own predecessor, never to whatever now
/// fills that slot: two parents flying apart spawn a child each every 0.1 s into a pool of
/// three slots, each child dead after 0.05 s. A child's predecessor has then always died,
/// and its slot has gone to the other parent's newest child, alive — so nothing may be
/// drawn (the parents themselves are black), on any of the frames looked at.
#[test]
fn a_ribbon_per_parent_never_joins_a_child_to_its_predecessors_reused_slot() {
    let mut effect = ribbon_effect_at(10.0);
    let parent = &mut effect.emitters[0];
    parent.capacity = 2;
    burst_at_start(parent, 2);
    parent.lifetime_secs = Range::new(5.0, 5.0);
    parent.transform.position_m = [0.0, 1.0, 0.0];
    parent.spread_deg = 180.0;
    parent.look.color_over_life = flat_color([0.0, 0.0, 0.0, 1.0]);
    let ribbon = &mut effect.emitters[1];
    ribbon.capacity = 3;
    ribbon.lifetime_secs = Range::new(0.05, 0.05);
    ribbon.look.size_m = Param::Constant(0.05);
    ribbon.look.color_over_life = flat_color([1.0, 1.0, 1.0, 1.0]);
    ribbon.look.trail = Some(Trail {
        mode: TrailMode::PerParent,
        draw_sprite: false,
        ..Trail::default()
    });
    let mut run = side_view_run(effect);
    let mut children = 0;
    for frame in 0..40 {
        run.advance(f64::from(DT));
        children += run
            .player
            .particles(run.instance, 1)
            .expect("read")
            .iter()
            .filter(|p| p.is_alive())
            .count();
        if frame % 2 == 1 {
            let light = total_light(&run.render((160, 120)).expect("render"));
            assert_eq!(
                light, 0.0,
                "frame {frame}: a ribbon drawn between living children"
            );
        }
    }
    assert!(children > 24, "only {children} living children seen");
}

/// A headless run of `effect` in [`side_view`] (checked valid first).
fn side_view_run(mut effect: Effect) -> ignis::testing::headless::Headless {
    side_view(&mut effect);
    effect.validate().expect("valid");
    ignis::testing::headless::Headless::new(&gpu(), effect, ShaderLibrary::embedded())
        .expect("headless")
}

/// `e` spawns `count` particles at time 0 and none after.
fn burst_at_start(e: &mut Emitter, count: u32) {
    e.spawn_rate_per_sec = Param::Constant(0.0);
    e.bursts = vec![Burst {
        time_secs: 0.0,
        count,
    }];
}
