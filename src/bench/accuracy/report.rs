//! The accuracy bench's report: one section per scene (a row per integrator and state
//! layout, the cheapest integrator per error bound), the frame-rate section, the CSV and
//! the plot.

use super::*;
use crate::bench::Report;
use crate::bench::report::sci;

/// Options of `ignis bench accuracy`.
pub struct AccuracyOptions {
    /// Particles per error run.
    pub particles: u32,
    /// Capacity for the cost runs (0 = automatic: 1M on a CPU adapter, 16M otherwise).
    pub cost_capacity: u32,
    /// Timed repeats per cost point.
    pub repeats: usize,
}

/// What the scene sections gather for the JSON, the CSV and the plot.
#[derive(Default)]
struct Gathered {
    points: Vec<ErrorPoint>,
    costs: Vec<(Scene, Integrator, f64)>,
    packed_costs: Vec<serde_json::Value>,
    csv: String,
    scenes: Vec<serde_json::Value>,
}

/// (dt, RMS error) at every dt of one run.
type DtErrors = Vec<(f64, f64)>;

/// One integrator's errors at every dt and its cost, for the frontier.
type FrontierPoint = (Integrator, DtErrors, f64);

/// Runs the whole accuracy bench and returns its report (also writes CSV and SVG into
/// `out_dir`).
pub fn run(
    ctx: &GpuContext,
    opts: &AccuracyOptions,
    out_dir: &std::path::Path,
) -> anyhow::Result<Report> {
    let mut report = Report::new("ignis bench accuracy", ctx);
    let timer = GpuTimer::new(ctx);
    let cost_capacity = if opts.cost_capacity > 0 {
        opts.cost_capacity
    } else if ctx.profile.is_software() {
        1 << 20
    } else {
        1 << 24
    }
    .min(ctx.max_capacity() as u32);
    report.para(&format!(
        "Error: RMS and max over {} particles (scene 2: at most 512) of |x − x_ref| / \
         |x_ref − x0| at T = {T_SECS} s, all runs from the same initial state. \
         Cost: update pass, ns per particle-step at {} particles, median of {} runs of 8 steps, \
         measured with **{}**. Order: least-squares slope of log RMS error vs log dt over the \
         points with 1e-5 < error < 0.3.",
        opts.particles,
        cost_capacity,
        opts.repeats,
        timer.source.label()
    ));
    let mut gathered = Gathered {
        csv: "scene,integrator,dt_secs,rms_rel_error,max_rel_error,cost_ns_per_particle_step\n"
            .into(),
        ..Default::default()
    };
    for scene in [Scene::ClosedForm, Scene::Turbulent] {
        scene_section(ctx, opts, cost_capacity, scene, &mut report, &mut gathered)?;
    }
    let (frame_rate, all_equal) = frame_rate_section(ctx, opts, &mut report)?;

    let g = gathered;
    report.json["points"] = serde_json::to_value(&g.points)?;
    report.json["costs_ns_per_particle_step"] = serde_json::to_value(
        g.costs
            .iter()
            .map(|(s, i, c)| serde_json::json!({"scene": s, "integrator": i.label(), "ns": c}))
            .collect::<Vec<_>>(),
    )?;
    report.json["frontier"] = serde_json::Value::Array(g.scenes);
    report.json["packed_costs_ns_per_particle_step"] = serde_json::Value::Array(g.packed_costs);
    report.json["frame_rate"] = serde_json::Value::Array(frame_rate);
    report.json["fixed_step_bit_identical"] = serde_json::Value::Bool(all_equal);
    report.json["timing"] = serde_json::Value::String(timer.source.label().into());

    std::fs::create_dir_all(out_dir)?;
    crate::preset::write_atomic(&out_dir.join("accuracy.csv"), g.csv.as_bytes())?;
    plot_frontier(&out_dir.join("accuracy.svg"), &g.points, &g.costs)?;
    report.para("Plot: `accuracy.svg` — error vs cost, one line per integrator, one point per dt.");
    Ok(report)
}

/// One scene: every integrator on the full state, then the compact states for two of them;
/// a table row each, and the cheapest integrator per error bound at 60 Hz.
fn scene_section(
    ctx: &GpuContext,
    opts: &AccuracyOptions,
    cost_capacity: u32,
    scene: Scene,
    report: &mut Report,
    g: &mut Gathered,
) -> anyhow::Result<()> {
    report.heading(scene.label());
    eprintln!("bench accuracy: {}: reference solution", scene.label());
    let n = if scene == Scene::Turbulent {
        opts.particles.min(512)
    } else {
        opts.particles
    };
    let setup = setup_scene(ctx, scene, n)?;
    let runs = Integrator::ALL
        .iter()
        .map(|i| (*i, StateLayout::Full))
        .chain([
            (Integrator::SemiImplicitEuler, StateLayout::Packed),
            (Integrator::Rk4, StateLayout::Packed),
            (Integrator::SemiImplicitEuler, StateLayout::Tiny),
            (Integrator::Rk4, StateLayout::Tiny),
        ]);
    let mut rows = Vec::new();
    let mut frontier = Vec::new();
    for (integrator, layout) in runs {
        let label = compact_label(integrator, layout);
        eprintln!("bench accuracy: {} / {label}", scene.label());
        let cost = measure_cost(ctx, scene, integrator, cost_capacity, opts.repeats, layout)?;
        let (row, errs) = integrator_row(ctx, &setup, (integrator, layout), cost, g)?;
        if layout == StateLayout::Full {
            g.costs.push((scene, integrator, cost));
            frontier.push((integrator, errs, cost));
        } else {
            g.packed_costs
                .push(serde_json::json!({"scene": scene, "integrator": label, "ns": cost}));
        }
        rows.push(row);
    }
    let dt_labels: Vec<String> = DTS.iter().map(|d| format!("dt=1/{:.0}", 1.0 / d)).collect();
    let mut header = vec!["integrator"];
    header.extend(dt_labels.iter().map(|s| s.as_str()));
    header.extend(["order", "ns/particle-step"]);
    report.para(
        "Each cell: RMS / max relative position error. \"+ packed\" rows: the same runs on the \
         packed 20-byte state (f16 velocity with dithered rounding, 16-bit life fraction); \
         \"+ tiny\" rows: on the tiny 10-byte state (f16 position, shared-exponent velocity with \
         8 significant bits, exact ages from the birth table); the difference to the full-state \
         row of the same integrator is the packing's accuracy cost.",
    );
    report.table(&header, &rows);
    let lines = frontier_lines(&frontier);
    report.para(&format!(
        "Cheapest integrator meeting each error bound at dt = 1/60 s:\n\n{}",
        lines.join("\n")
    ));
    g.scenes
        .push(serde_json::json!({ "scene": scene, "frontier": lines }));
    Ok(())
}

/// One integrator on one state layout at every dt: its table row (errors, order, cost) and
/// its (dt, RMS error) points; the points and CSV lines go into `g`.
fn integrator_row(
    ctx: &GpuContext,
    setup: &SceneSetup,
    (integrator, layout): (Integrator, StateLayout),
    cost: f64,
    g: &mut Gathered,
) -> anyhow::Result<(Vec<String>, DtErrors)> {
    let mut errs = Vec::new();
    let mut row = vec![compact_label(integrator, layout)];
    for dt in DTS {
        let p = if layout == StateLayout::Full {
            measure_error(ctx, setup, integrator, dt)?
        } else {
            measure_error_compact(ctx, setup, integrator, dt, layout)?
        };
        row.push(format!(
            "{} / {}",
            sci(p.rms_rel_error),
            sci(p.max_rel_error)
        ));
        g.csv.push_str(&format!(
            "{:?},{},{},{},{},{}\n",
            p.scene, p.integrator, dt, p.rms_rel_error, p.max_rel_error, cost
        ));
        errs.push((dt, p.rms_rel_error));
        g.points.push(p);
    }
    let order = convergence_order(&errs);
    row.push(order.map_or("—".into(), |o| format!("{o:.2}")));
    row.push(format!("{cost:.3}"));
    Ok((row, errs))
}

/// "≤ x % error at 60 Hz: the cheapest integrator that meets it", for three bounds.
fn frontier_lines(frontier: &[FrontierPoint]) -> Vec<String> {
    [1e-2, 1e-3, 1e-4]
        .into_iter()
        .map(|target| {
            let best = frontier
                .iter()
                .filter(|(_, errs, _)| {
                    errs.iter()
                        .any(|(dt, e)| (*dt - 1.0 / 60.0).abs() < 1e-9 && *e <= target)
                })
                .min_by(|a, b| a.2.total_cmp(&b.2));
            format!(
                "- ≤ {:.2}% error at 60 Hz: **{}**",
                target * 100.0,
                best.map_or("none of them".to_owned(), |b| format!(
                    "{} ({:.3} ns/particle-step)",
                    b.0.label(),
                    b.2
                ))
            )
        })
        .collect()
}

/// Frame-rate (in)dependence: the fixed-step state hash of every frame sequence and the
/// frame-delta divergence. Returns the JSON rows and whether every hash is equal.
fn frame_rate_section(
    ctx: &GpuContext,
    opts: &AccuracyOptions,
    report: &mut Report,
) -> anyhow::Result<(Vec<serde_json::Value>, bool)> {
    report.heading("Frame-rate (in)dependence (2 s)");
    eprintln!("bench accuracy: frame-rate independence");
    let hashes = fixed_step_hashes(ctx)?;
    let all_equal = hashes.windows(2).all(|w| w[0].1 == w[1].1);
    let deltas = frame_delta_divergence(ctx, opts.particles)?;
    let reference = deltas
        .iter()
        .find(|d| d.0 == "240 fps")
        .map(|d| d.2.clone())
        .unwrap_or_default();
    let mut rows = Vec::new();
    let mut json = Vec::new();
    for ((name, hash, steps), (_, err, positions)) in hashes.iter().zip(&deltas) {
        let div = (positions
            .iter()
            .zip(&reference)
            .map(|(a, b)| (*a - *b).length_squared())
            .sum::<f64>()
            / positions.len().max(1) as f64)
            .sqrt();
        rows.push(vec![
            name.clone(),
            format!("{hash:016x} ({steps} steps)"),
            sci(*err),
            format!("{div:.4} m"),
        ]);
        json.push(serde_json::json!({
            "frames": name,
            "fixed_step_state_hash": format!("{hash:016x}"),
            "fixed_steps": steps,
            "frame_delta_rms_rel_error": err,
            "frame_delta_rms_divergence_vs_240fps_m": div,
        }));
    }
    report.para(&format!(
        "Fixed step (default campfire, all three emitters, 1/120 s steps): final state **{}** \
         across every frame sequence. Frame delta (scene 1, explicit Euler — the 2006 thesis's \
         setup): error against the exact solution and RMS distance of the final positions from \
         the 240 fps run.",
        if all_equal {
            "bit-identical"
        } else {
            "NOT identical"
        }
    ));
    report.table(
        &[
            "frames",
            "fixed step: state hash",
            "frame delta: RMS rel. error vs exact",
            "frame delta: RMS divergence vs 240 fps",
        ],
        &rows,
    );
    Ok((json, all_equal))
}

/// Error (y, log) against cost per simulated second (x, log): one line per integrator and
/// scene, a point per dt.
fn plot_frontier(
    path: &std::path::Path,
    points: &[ErrorPoint],
    costs: &[(Scene, Integrator, f64)],
) -> anyhow::Result<()> {
    use plotters::prelude::*;
    let root = SVGBackend::new(path, (960, 540)).into_drawing_area();
    root.fill(&WHITE)?;
    let series: Vec<(String, Vec<(f64, f64)>)> = costs
        .iter()
        .map(|(scene, integrator, ns)| {
            let pts = points
                .iter()
                .filter(|p| p.scene == *scene && p.integrator == integrator.label())
                .map(|p| (ns / p.dt_secs, p.rms_rel_error.clamp(1e-9, 10.0)))
                .collect();
            let tag = if *scene == Scene::ClosedForm {
                "s1"
            } else {
                "s2"
            };
            (format!("{} ({tag})", integrator.label()), pts)
        })
        .collect();
    let xs = series.iter().flat_map(|s| s.1.iter().map(|p| p.0));
    let (xmin, xmax) = xs.fold((f64::MAX, f64::MIN), |(a, b), x| (a.min(x), b.max(x)));
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "ignis: error vs cost (ns per particle per simulated second)",
            ("sans-serif", 20),
        )
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(
            (xmin * 0.8..xmax * 1.25).log_scale(),
            (1e-9f64..10.0).log_scale(),
        )?;
    chart
        .configure_mesh()
        .x_desc("cost: ns per particle per simulated second")
        .y_desc("RMS relative position error at T = 2 s")
        .draw()?;
    for (i, (name, pts)) in series.iter().enumerate() {
        let color = Palette99::pick(i).to_rgba();
        chart
            .draw_series(LineSeries::new(pts.iter().copied(), color.stroke_width(2)))?
            .label(name.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], color));
        chart.draw_series(pts.iter().map(|p| Circle::new(*p, 3, color.filled())))?;
    }
    crate::tune::svg::legend_and_present(&mut chart, &root)?;
    Ok(())
}
