//! Trails on a real adapter: the points a ribbon is drawn through are the particle's own
//! positions after the steps that recorded them (the ring read back, its entries chosen as
//! the vertex shader chooses them), a reused slot's ribbon holds only its new particle's
//! points, and the drawn ribbon lights the pixels between the particle and its tail.

mod common;

use common::*;
use ignis::effect::*;
use ignis::shaders::ShaderLibrary;
use ignis::sim::GpuSim;
use ignis::sim::trails::trail_indices;

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
        every_steps: every,
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
                let got = ring.entries[slot * points as usize + r as usize];
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

/// One particle flying straight across the view with a ribbon and no sprite: the lit
/// pixels run from the particle back to its oldest point, not beyond.
#[test]
fn the_ribbon_lights_the_pixels_between_the_particle_and_its_tail() {
    let ctx = gpu();
    let (points, every) = (9u32, 2u32);
    let mut e = plain_emitter();
    e.capacity = 4;
    e.spawn_rate_per_sec = Param::Constant(0.0);
    e.bursts = vec![Burst {
        time_secs: 0.0,
        count: 1,
    }];
    e.lifetime_secs = Range::new(5.0, 5.0);
    e.transform.position_m = [-1.0, 1.0, 0.0];
    e.direction = [1.0, 0.0, 0.0];
    e.speed_m_per_s = Range::new(1.2, 1.2);
    e.look.size_m = Param::Constant(0.05);
    e.look.trail = Some(Trail {
        points,
        every_steps: every,
        width: 1.0,
        tail_width: 1.0,
        tail_opacity: 1.0,
        draw_sprite: false,
    });
    e.look.color_over_life = flat_color([1.0, 1.0, 1.0, 1.0]);
    e.look.intensity = 4.0;
    let mut effect = bare_effect(e);
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
    let mut run =
        ignis::headless::Headless::new(&ctx, effect, ShaderLibrary::embedded()).expect("headless");
    let frames = 60u32;
    for _ in 0..frames {
        run.advance(f64::from(DT));
    }
    let (w, h) = (320u32, 240u32);
    let image = run.render((w, h)).expect("render");
    // Born half way through the first step at x = −1, at 1.2 m/s: after step k it is at
    // −1 + 1.2 (k + ½) dt. The particle is drawn between its states after the last two
    // steps; the oldest point is the state after the oldest recording step shown.
    let px_per_m = (h as f32 / 2.0) / (3.0 * (22.5f32).to_radians().tan());
    let to_px = |x: f32| w as f32 / 2.0 + x * px_per_m;
    let after = |k: i64| -1.0 + 1.2 * (k as f32 + 0.5) * DT;
    let last_step = i64::from(frames) - 1;
    let (head_lo, head_hi) = (to_px(after(last_step - 1)), to_px(after(last_step)));
    let oldest_step = point_steps(points, every, u64::from(frames))
        .last()
        .copied()
        .expect("points");
    let tail = to_px(after(oldest_step));
    let row = h / 2;
    let lit: Vec<u32> = (0..w)
        .filter(|&x| image.get_pixel(x, row)[0] > 40)
        .collect();
    let (first, last) = (*lit.first().expect("lit pixels"), *lit.last().expect("lit"));
    assert!(
        (first as f32 - tail).abs() <= 2.0
            && (head_lo - 2.0..=head_hi + 2.0).contains(&(last as f32)),
        "lit {first}..={last}, ribbon from {tail:.1} to {head_lo:.1}..{head_hi:.1}"
    );
    assert_eq!(lit.len() as u32, last - first + 1, "one unbroken ribbon");
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
