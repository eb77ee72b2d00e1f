//! The peer bench: ignis's sphere workload (`bench/scenes/sphere_*.ron`) in bevy_hanabi,
//! headless, timed on the GPU. N additive particles in a 1 m sphere, 2 s lives (N/2 born
//! a second), up to 0.3 m/s in any direction, gravity 0.5 m/s² and linear drag 0.5/s,
//! 0.0092 m discs (3 px at 1920×1080 from 4 m with a 45° field of view), their colour
//! (1, 0.8, 0.4) → (1, 0.4, 0.1) over life at the scene's intensity, into an HDR camera. Each N is played past its lifetime, then its frames are timed: the whole
//! render graph (hanabi's simulation, the camera's passes) by two timestamps of our own
//! around it, and Bevy's own span of the transparent pass, where hanabi draws additive
//! particles. Writes `hanabi-<adapter>.json` and a PNG of the last frame per N.
//!
//! `cargo run --release -p bench_hanabi -- --counts 1048576,4194304 --out DIR`
//! (`scripts/peers.sh` runs it beside `ignis bench presets` on the same scenes).

// The headless Bevy app the plugin's examples and tests run on (no ignis in it).
#[path = "../../bevy_ignis/examples/common/bevy_headless.rs"]
mod bevy_headless;
mod capture;
mod stamps;
mod workload;

use std::path::PathBuf;

/// The command line.
struct Options {
    counts: Vec<u32>,
    frames: usize,
    size: (u32, u32),
    out: PathBuf,
}

fn parse() -> Result<Options, String> {
    let mut o = Options {
        counts: vec![1 << 20, 1 << 22, 1 << 24],
        frames: 30,
        size: (1920, 1080),
        out: PathBuf::from("bench/results/peers"),
    };
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let value = args.next().ok_or(format!("{a} needs a value"))?;
        let bad = |e: &dyn std::fmt::Display| format!("{a} {value}: {e}");
        match a.as_str() {
            "--counts" => {
                o.counts = value
                    .split(',')
                    .map(|c| c.trim().parse::<u32>().map_err(|e| bad(&e)))
                    .collect::<Result<_, _>>()?;
            }
            "--frames" => o.frames = value.parse().map_err(|e| bad(&e))?,
            "--size" => {
                let (w, h) = value.split_once('x').ok_or(bad(&"expected WxH"))?;
                o.size = (
                    w.parse().map_err(|e| bad(&e))?,
                    h.parse().map_err(|e| bad(&e))?,
                );
            }
            "--out" => o.out = PathBuf::from(value),
            _ => {
                return Err(format!(
                    "unknown option {a} (--counts, --frames, --size, --out)"
                ));
            }
        }
    }
    Ok(o)
}

fn main() {
    let opts = match parse() {
        Ok(o) => o,
        Err(e) => {
            eprintln!("bench_hanabi: {e}");
            std::process::exit(2);
        }
    };
    if let Err(e) = std::fs::create_dir_all(&opts.out) {
        eprintln!("bench_hanabi: cannot create {}: {e}", opts.out.display());
        std::process::exit(1);
    }
    let mut rows = Vec::new();
    let mut adapter = String::from("unknown");
    for &n in &opts.counts {
        let run = workload::run(n, opts.size, opts.frames, &opts.out);
        adapter = run.adapter.clone();
        println!(
            "{n:>9} particles: frame {:.3} ms, transparent pass {:.3} ms, rest {:.3} ms",
            run.frame_ms,
            run.draw_ms,
            run.frame_ms - run.draw_ms
        );
        rows.push(run);
    }
    let slug: String = adapter
        .to_lowercase()
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
        .collect();
    let json = workload::to_json(&adapter, &opts, &rows);
    let path = opts.out.join(format!("hanabi-{slug}.json"));
    match std::fs::write(&path, json) {
        Ok(()) => println!("wrote {}", path.display()),
        Err(e) => {
            eprintln!("bench_hanabi: cannot write {}: {e}", path.display());
            std::process::exit(1);
        }
    }
}
