//! A bench report: Markdown text printed and saved, plus machine-readable JSON.

use std::path::Path;

use crate::gpu::GpuContext;

/// Accumulates a Markdown report and a JSON value.
pub struct Report {
    /// The Markdown text.
    pub markdown: String,
    /// The JSON document.
    pub json: serde_json::Value,
}

impl Report {
    /// A report headed with the title, machine and command line.
    pub fn new(title: &str, ctx: &GpuContext) -> Self {
        let command = std::env::args().collect::<Vec<_>>().join(" ");
        let info = &ctx.info;
        let markdown = format!(
            "# {title}\n\n- adapter: {} ({:?}, {:?})\n- driver: {} {}\n- command: \
                `{command}`\n- date: {}\n\n",
            info.name,
            info.device_type,
            info.backend,
            info.driver,
            info.driver_info,
            humantime::format_rfc3339_seconds(std::time::SystemTime::now())
        );
        let json = serde_json::json!({
            "title": title,
            "adapter": info.name,
            "device_type": format!("{:?}", info.device_type),
            "backend": format!("{:?}", info.backend),
            "driver": format!("{} {}", info.driver, info.driver_info),
            "command": command,
        });
        Self { markdown, json }
    }

    /// Appends a section heading.
    pub fn heading(&mut self, text: &str) {
        self.markdown.push_str(&format!("\n## {text}\n\n"));
    }

    /// Appends a paragraph.
    pub fn para(&mut self, text: &str) {
        self.markdown.push_str(text);
        self.markdown.push_str("\n\n");
    }

    /// Appends a Markdown table.
    pub fn table(&mut self, header: &[&str], rows: &[Vec<String>]) {
        self.markdown
            .push_str(&format!("| {} |\n", header.join(" | ")));
        self.markdown.push_str(&format!(
            "|{}\n",
            header.iter().map(|_| "---|").collect::<String>()
        ));
        for r in rows {
            self.markdown.push_str(&format!("| {} |\n", r.join(" | ")));
        }
        self.markdown.push('\n');
    }

    /// Writes `NAME.md` and `NAME.json` into `dir` and prints the Markdown.
    pub fn save(&self, dir: &Path, name: &str) -> std::io::Result<()> {
        std::fs::create_dir_all(dir)?;
        crate::preset::write_atomic(&dir.join(format!("{name}.md")), self.markdown.as_bytes())?;
        let json = serde_json::to_string_pretty(&self.json).map_err(std::io::Error::other)?;
        crate::preset::write_atomic(&dir.join(format!("{name}.json")), json.as_bytes())?;
        Ok(())
    }
}

/// Formats a number in engineering style for tables.
pub fn sci(x: f64) -> String {
    if !x.is_finite() {
        return "diverged".into();
    }
    if x == 0.0 {
        return "0".into();
    }
    format!("{x:.2e}")
}
