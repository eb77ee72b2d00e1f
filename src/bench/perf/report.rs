//! The perf bench's tables: the rows, modules and sorts as Markdown and JSON.

use super::*;

/// The compact state layouts the bench measures beside the full state, and their names.
pub(super) const COMPACT: [(StateLayout, &str); 2] =
    [(StateLayout::Packed, "packed"), (StateLayout::Tiny, "tiny")];

/// The throughput rows as they are measured: the main table, the tile path's stages, the
/// JSON rows and, per compact layout ([`COMPACT`]), its table and JSON rows.
#[derive(Default)]
pub(super) struct Tables {
    pub(super) table: Vec<Vec<String>>,
    pub(super) tile_table: Vec<Vec<String>>,
    pub(super) rows: Vec<serde_json::Value>,
    pub(super) compact_tables: [Vec<Vec<String>>; 2],
    pub(super) compact_rows: [Vec<serde_json::Value>; 2],
}

impl Tables {
    /// Measures row `side`² on a device of its own, as a fresh process has: after a large
    /// pool is freed, small work on the same device runs 2–5× slower on the H100 (not
    /// memory we keep: its allocator holds nothing then; a new device is fast again). The
    /// compact states are measured from 1M particles up (below, launch overheads dominate).
    pub(super) fn measure_side(
        &mut self,
        ctx: &GpuContext,
        opts: &PerfOptions,
        side: u32,
        report: &mut Report,
    ) -> anyhow::Result<()> {
        let n = side as u64 * side as u64;
        eprintln!("bench perf: {side}² = {n} particles");
        let row_ctx = GpuContext::headless()?.with_profile(Some(ctx.profile));
        let ctx = &row_ctx;
        let copy = copy_pipeline(ctx, COPY_WGSL);
        let copy20 = copy_pipeline(ctx, COPY20_WGSL);
        let row = measure_row(ctx, opts, n, &copy)?;
        self.push_row(side, n, &row);
        for (k, (layout, name)) in COMPACT.iter().enumerate() {
            if n < 1 << 20 {
                break;
            }
            eprintln!("bench perf: {side}² {name}");
            match measure_compact(ctx, opts, n, *layout, &copy20) {
                Ok(p) => self.push_compact(k, side, n, 2.0 * layout.slot_bytes() as f64, &p, &row),
                Err(e) => report.para(&format!("{side}² {name}: {e}")),
            }
        }
        Ok(())
    }

    /// Row `side`² = `n` of the throughput and tile-stage tables and the JSON.
    pub(super) fn push_row(&mut self, side: u32, n: u64, row: &PerfRow) {
        if let (Some(all), Some([project, bin]), Some((by_compute, by_draw))) = (
            row.draws.tiles_ms,
            row.draws.tiles_stages_ms,
            row.draws.tiles_resolve_ms,
        ) {
            self.tile_table.push(vec![
                format!("{side}² = {n}"),
                format!("{project:.3}"),
                format!("{:.3}", bin - project),
                format!("{:.3}", all - bin),
                format!("{all:.3}"),
                by_compute.map_or_else(|| "—".into(), |ms| format!("{ms:.3}")),
                format!("{by_draw:.3}"),
            ]);
        }
        let gbps = n as f64 * 64.0 / (row.lean_update_ms * 1e-3) / 1e9;
        let copy_gbps = n as f64 * 64.0 / (row.copy_ms * 1e-3) / 1e9;
        let thesis = THESIS_FPS.iter().find(|(s, _)| *s == side).map(|(_, f)| *f);
        let fps = 1000.0 / row.frame_ms;
        self.table.push(vec![
            format!("{side}² = {n}"),
            format!("{:.3}", row.update_ms),
            format!("{:.3}", row.lean_update_ms),
            format!("{:.3}", row.copy_ms),
            format!(
                "{gbps:.3} GB/s ({:.0} % of the copy's {copy_gbps:.3})",
                100.0 * row.copy_ms / row.lean_update_ms
            ),
            row.draws
                .billboard_ms
                .map_or("skipped".into(), |m| format!("{m:.3}")),
            format!("{:.3}", row.draws.splat_ms),
            row.draws.tiles_ms.map_or("—".into(), |m| format!("{m:.3}")),
            format!("{:.3}", row.draws.composite_ms),
            format!("{:.3} ({})", row.frame_ms, row.draws.auto_path),
            format!("{fps:.0}"),
            thesis.map_or("—".into(), |t| format!("{t:.0} (ours: {:.2}×)", fps / t)),
            sci(n as f64 * fps),
        ]);
        self.rows.push(serde_json::json!({
            "side": side, "row": row, "update_gb_per_s": gbps, "copy_gb_per_s": copy_gbps,
            "update_vs_copy": row.copy_ms / row.lean_update_ms, "fps": fps, "thesis_fps": thesis,
        }));
    }

    /// Compact layout `k`'s row `side`² = `n` (`moved` bytes per particle-step), against
    /// the full state's `row`.
    pub(super) fn push_compact(
        &mut self,
        k: usize,
        side: u32,
        n: u64,
        moved: f64,
        p: &PackedRow,
        row: &PerfRow,
    ) {
        let pgbps = n as f64 * moved / (p.update_ms * 1e-3) / 1e9;
        let pcopy = n as f64 * moved / (p.copy_ms * 1e-3) / 1e9;
        self.compact_tables[k].push(vec![
            format!("{side}² = {n}"),
            format!("{:.3}", p.update_ms),
            format!("{:.3}", row.lean_update_ms),
            format!("{:.2}×", row.lean_update_ms / p.update_ms),
            format!("{:.3}", p.copy_ms),
            format!(
                "{pgbps:.3} GB/s ({:.0} % of the copy's {pcopy:.3})",
                100.0 * p.copy_ms / p.update_ms
            ),
        ]);
        self.compact_rows[k].push(serde_json::json!({
            "side": side, "row": p, "full_update_ms": row.lean_update_ms,
            "bytes_moved_per_particle_step": moved,
            "update_gb_per_s": pgbps, "copy_gb_per_s": pcopy,
            "update_vs_copy": p.copy_ms / p.update_ms,
        }));
    }

    /// Writes the throughput, tile-stage and compact-state sections and their JSON.
    pub(super) fn report(self, report: &mut Report) {
        let Tables {
            table,
            tile_table,
            rows,
            compact_tables,
            compact_rows,
        } = self;
        report.heading("Throughput");
        report.table(
            &[
                "particles",
                "update ms (campfire flames: turbulence + flame pull)",
                "update ms (without them)",
                "copy ms",
                "update bandwidth, without them (vs copy)",
                "billboard draw ms",
                "splat draw ms (clear + splat)",
                "tile draw ms (project, bin, shade, resolve)",
                "composite ms (tonemap + splat resolve)",
                "frame ms (auto path)",
                "fps",
                "2006 thesis fps (ours ×)",
                "particles/s",
            ],
            &table,
        );
        report.heading("Tile path stages");
        report.para(
            "The tile draw of each row timed stage by stage (records that stop after a stage, same run): \
             project every quad, bin (count per block, scan, list; then the dense bins' lists per tile), then shade and resolve (the rest). \
             The last two columns time the resolve of the shaded tiles into the HDR image alone: by compute \
             (the tile draw's, as in the editor, where the adapter reads and writes the image in place) and by a draw \
             (what a host's render pass gets).",
        );
        report.table(
            &[
                "particles",
                "project ms",
                "bin ms",
                "shade + resolve ms",
                "tile draw ms",
                "resolve ms (compute)",
                "resolve ms (draw)",
            ],
            &tile_table,
        );
        let [packed_table, tiny_table] = compact_tables;
        let [packed_rows, tiny_rows] = compact_rows;
        let compact_header = |what: &str| {
            [
                "particles".to_string(),
                format!("{what} update ms"),
                "full update ms (above, without turbulence)".into(),
                "speed-up".into(),
                "copy ms (20 B elements)".into(),
                format!("{what} bandwidth (vs copy)"),
            ]
        };
        report.heading("Packed state (20 B per particle)");
        report.para(
            "The `packed_state` option: f32 position, f16 velocity, 16-bit life fraction, lifetime re-derived \
             from the spawn hash — 40 B moved per particle-step (20 read + 20 written) instead of 64. The copy \
             moves the same 20-byte elements in the same run. Accuracy cost: `ignis bench accuracy` (\"+ packed\" rows).",
        );
        report.table(
            &compact_header("packed").each_ref().map(String::as_str),
            &packed_table,
        );
        report.json["packed"] = serde_json::Value::Array(packed_rows);
        report.heading("Tiny state (10 B per particle)");
        report.para(
            "The `tiny_state` option: f16 position, shared-exponent velocity (8 significant bits of the largest \
             component), no age (each step's births are in a table the update reads, so ages are exact) and no \
             lifetime (re-derived) — 20 B moved per particle-step (10 read + 10 written). One invocation updates a \
             pair of slots (they share a word); the copy moves the same bytes as 20-byte pairs in the same run. \
             Accuracy cost: `ignis bench accuracy` (\"+ tiny\" rows).",
        );
        report.table(
            &compact_header("tiny").each_ref().map(String::as_str),
            &tiny_table,
        );
        report.json["tiny"] = serde_json::Value::Array(tiny_rows);
        report.json["rows"] = serde_json::Value::Array(rows);
    }
}

/// Writes the optional modules' section (`costs`: variant, median ms, best ms).
pub(super) fn report_modules(
    report: &mut Report,
    ctx: &GpuContext,
    opts: &PerfOptions,
    costs: &[(String, f64, f64)],
) -> anyhow::Result<()> {
    report.heading("Optional modules");
    let bare = costs.first().map_or(f64::NAN, |c| c.2);
    let mcap = opts.module_capacity.min(ctx.max_capacity() as u32);
    report.para(&format!(
        "Update pass at {mcap} particles, ms per step: the median and the best of {} one-step submissions in {} rounds \
         over the variants, all on one full pool (several large pools alive at once slow every one of them on the \
         H100), each after 100 ms of untimed steps; stateless mode, which clears the pool, last. The comparison uses \
         the best: on the H100 a share of samples runs in a slow state (0.42 → 0.75 ms for the same step, bimodal), which moves medians by tens of percent while the best repeats to 1 %. \
         The first two rows are the \"off costs nothing\" check: the pipeline with every module compiled out \
         by its override constant against one built from source with the module code deleted.",
        opts.repeats.max(1) * super::costs::MODULE_ROUNDS,
        super::costs::MODULE_ROUNDS
    ));
    let mrows: Vec<Vec<String>> = costs
        .iter()
        .map(|(name, ms, best)| {
            vec![
                name.clone(),
                format!("{ms:.4}"),
                format!("{best:.4}"),
                format!("{:+.1} %", 100.0 * (best / bare - 1.0)),
            ]
        })
        .collect();
    report.table(
        &["variant", "update ms/step (median)", "best", "best vs bare"],
        &mrows,
    );
    report.json["modules"] = serde_json::to_value(
        costs
            .iter()
            .map(|(n, ms, best)| serde_json::json!({"variant": n, "ms": ms, "best_ms": best}))
            .collect::<Vec<_>>(),
    )?;
    Ok(())
}

/// Writes the sorting section and its JSON.
pub(super) fn report_sorts(report: &mut Report, sorts: &[SortRow]) -> anyhow::Result<()> {
    report.heading("Sorting (alpha-blended emitters)");
    report.para(
        "Back-to-front order of (depth key, slot) pairs: the bitonic network split so that every run of stages \
         with a compare distance below 512 is one dispatch in workgroup memory, against the plain network (one \
         global dispatch per stage), same keys, same run. In a frame only the emitter's live window is sorted.",
    );
    let srows: Vec<Vec<String>> = sorts
        .iter()
        .map(|r| {
            vec![
                r.keys.to_string(),
                format!("{} / {}", r.split_dispatches, r.plain_dispatches),
                format!("{:.3}", r.split_ms),
                format!("{:.3}", r.plain_ms),
                format!("{:.2}×", r.plain_ms / r.split_ms),
            ]
        })
        .collect();
    report.table(
        &[
            "keys",
            "dispatches (split / plain)",
            "split ms",
            "plain ms",
            "speed-up",
        ],
        &srows,
    );
    report.json["sort"] = serde_json::to_value(sorts)?;
    Ok(())
}
