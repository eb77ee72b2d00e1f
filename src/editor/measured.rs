//! The accuracy and cost of each integrator as the accuracy bench measured them on the
//! H100 (`bench/results/accuracy-nvidia-h100-80gb.json`): data the Time section shows,
//! embedded in the binary (the editor reads the results; it does not call the bench).

use crate::effect::Integrator;

/// The committed H100 accuracy results, embedded so the editor can show what each
/// integrator costs and how accurate it is (`bench/results/accuracy-nvidia-h100-80gb.json`).
pub const MEASURED_JSON: &str = include_str!("../../bench/results/accuracy-nvidia-h100-80gb.json");

/// One measured figure for the panel.
#[derive(Clone, Debug, PartialEq)]
pub struct Measured {
    /// Scene label.
    pub scene: &'static str,
    /// The measured step size nearest to the asked one, seconds.
    pub dt_secs: f64,
    /// RMS relative position error at T = 2 s.
    pub rms_rel_error: f64,
    /// Update cost, ns per particle-step (H100, GPU timestamps).
    pub cost_ns: f64,
}

/// What the accuracy bench measured for `integrator` at the step nearest `dt_secs`, in
/// both scenes (empty when the embedded results lack it).
pub fn measured_for(integrator: Integrator, dt_secs: f64) -> Vec<Measured> {
    let Ok(doc) = serde_json::from_str::<serde_json::Value>(MEASURED_JSON) else {
        return Vec::new();
    };
    let label = integrator.label();
    let mut out = Vec::new();
    for (scene, name) in [("ClosedForm", "closed form"), ("Turbulent", "turbulent")] {
        let best = doc["points"]
            .as_array()
            .into_iter()
            .flatten()
            .filter(|p| p["scene"] == scene && p["integrator"] == label)
            .min_by(|a, b| {
                let da = (a["dt_secs"].as_f64().unwrap_or(0.0).ln() - dt_secs.ln()).abs();
                let db = (b["dt_secs"].as_f64().unwrap_or(0.0).ln() - dt_secs.ln()).abs();
                da.total_cmp(&db)
            });
        let cost = doc["costs_ns_per_particle_step"]
            .as_array()
            .into_iter()
            .flatten()
            .find(|c| c["scene"] == scene && c["integrator"] == label)
            .and_then(|c| c["ns"].as_f64());
        if let (Some(p), Some(cost_ns)) = (best, cost) {
            out.push(Measured {
                scene: name,
                dt_secs: p["dt_secs"].as_f64().unwrap_or(f64::NAN),
                rms_rel_error: p["rms_rel_error"].as_f64().unwrap_or(f64::NAN),
                cost_ns,
            });
        }
    }
    out
}
