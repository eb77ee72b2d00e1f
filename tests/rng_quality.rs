//! Randomness quality of the counter-based hash (the same integer maths runs on the GPU;
//! `core_sim::gpu_matches_cpu_reference_for_every_integrator` checks the two agree).

use ignis::testing::rng::{emitter_salt, rand_block, spawn_key, unorm, unorm4};

const N: u64 = 200_000;

fn samples(block: u32, lane: usize) -> Vec<f32> {
    let salt = emitter_salt(0, 0);
    (0..N)
        .map(|i| {
            let slot = (i % 4096) as u32;
            unorm4(rand_block(spawn_key(42, salt, slot, i), block))[lane]
        })
        .collect()
}

/// Chi-square over 100 bins, for every lane of the first two blocks: with 99 degrees of
/// freedom the 99.9th percentile is 148.2.
#[test]
fn unit_interval_outputs_are_uniform() {
    for block in 0..2 {
        for lane in 0..4 {
            let xs = samples(block, lane);
            let mut bins = [0u64; 100];
            for x in &xs {
                assert!((0.0..1.0).contains(x));
                bins[(*x * 100.0) as usize] += 1;
            }
            let expected = N as f64 / 100.0;
            let chi2: f64 = bins
                .iter()
                .map(|&b| (b as f64 - expected).powi(2) / expected)
                .sum();
            assert!(chi2 < 148.2, "block {block} lane {lane}: chi² = {chi2:.1}");
            let mean = xs.iter().map(|&x| x as f64).sum::<f64>() / N as f64;
            assert!((mean - 0.5).abs() < 0.005, "mean {mean}");
        }
    }
}

fn correlation(a: &[f32], b: &[f32]) -> f64 {
    let n = a.len() as f64;
    let ma = a.iter().map(|&x| x as f64).sum::<f64>() / n;
    let mb = b.iter().map(|&x| x as f64).sum::<f64>() / n;
    let cov: f64 = a
        .iter()
        .zip(b)
        .map(|(&x, &y)| (x as f64 - ma) * (y as f64 - mb))
        .sum();
    let va: f64 = a.iter().map(|&x| (x as f64 - ma).powi(2)).sum();
    let vb: f64 = b.iter().map(|&y| (y as f64 - mb).powi(2)).sum();
    cov / (va * vb).sqrt()
}

/// Neighbouring slots (consecutive spawns) and the lanes within one spawn are
/// uncorrelated: |r| < 0.01 (4.5σ at 200k samples).
#[test]
fn no_correlation_between_neighbouring_slots_or_lanes() {
    let x = samples(0, 0);
    let r_next = correlation(&x[..x.len() - 1], &x[1..]);
    assert!(r_next.abs() < 0.01, "slot i vs i+1: r = {r_next}");
    let r_far = correlation(&x[..x.len() - 4096], &x[4096..]);
    assert!(
        r_far.abs() < 0.01,
        "same slot, next lap of the ring: r = {r_far}"
    );
    let y = samples(0, 1);
    let z = samples(1, 0);
    assert!(correlation(&x, &y).abs() < 0.01);
    assert!(correlation(&x, &z).abs() < 0.01);
}

/// Different seeds, emitters and spawn counters give different streams; the 64-bit spawn
/// counter's high word matters (no repetition after 2^32 spawns).
#[test]
fn streams_differ_by_seed_emitter_and_counter() {
    let salt0 = emitter_salt(0, 0);
    let salt1 = emitter_salt(1, 0);
    let k = |seed, salt, i: u64| rand_block(spawn_key(seed, salt, (i % 1000) as u32, i), 0);
    assert_ne!(k(1, salt0, 5), k(2, salt0, 5));
    assert_ne!(k(1, salt0, 5), k(1, salt1, 5));
    assert_ne!(k(1, salt0, 5), k(1, salt0, 5 + (1u64 << 32)));
    // 1e6 consecutive spawns: no repeated first word pair.
    let mut seen = std::collections::HashSet::new();
    for i in 0..1_000_000u64 {
        let w = k(9, salt0, i);
        assert!(seen.insert((w[0], w[1])), "repeated stream at spawn {i}");
    }
    assert_eq!(unorm(u32::MAX), 16_777_215.0 / 16_777_216.0);
}
