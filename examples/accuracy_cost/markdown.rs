//! The report's text: markdown tables, number formatting, and the assembly of the sections
//! under a "what to choose when" summary built from each section's conclusions.

use std::fmt::Write;

/// One section of the report.
pub struct Section {
    /// Heading.
    pub title: String,
    /// Markdown body: prose, tables, plot links.
    pub body: String,
    /// One-line conclusions drawn from the numbers, gathered at the top of the report.
    pub conclusions: Vec<String>,
}

/// A markdown table built row by row.
pub struct Table {
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Table {
    /// A table with these column titles.
    pub fn new(header: &[&str]) -> Self {
        Self {
            header: header.iter().map(|h| h.to_string()).collect(),
            rows: Vec::new(),
        }
    }

    /// Appends a row (as many cells as columns).
    pub fn row(&mut self, cells: Vec<String>) {
        debug_assert_eq!(cells.len(), self.header.len());
        self.rows.push(cells);
    }

    /// The table in GitHub markdown, numbers right-aligned (every column but the first).
    pub fn to_markdown(&self) -> String {
        let mut s = String::new();
        let line = |cells: &[String]| format!("| {} |\n", cells.join(" | "));
        s.push_str(&line(&self.header));
        let align: Vec<String> = (0..self.header.len())
            .map(|i| if i == 0 { "---".into() } else { "---:".into() })
            .collect();
        s.push_str(&line(&align));
        for r in &self.rows {
            s.push_str(&line(r));
        }
        s
    }
}

/// `x` to 3 significant digits, in scientific notation when very small or large; "—" when not
/// finite (a diverged run).
pub fn sig(x: f64) -> String {
    if !x.is_finite() {
        return "—".into();
    }
    let a = x.abs();
    if a == 0.0 {
        "0".into()
    } else if !(1e-3..1e5).contains(&a) {
        format!("{x:.2e}")
    } else {
        let decimals = (2 - a.log10().floor() as i32).max(0) as usize;
        format!("{x:.decimals$}")
    }
}

/// A fraction as a percentage with one decimal.
pub fn percent(x: f64) -> String {
    if x.is_finite() {
        format!("{:.1} %", 100.0 * x)
    } else {
        "—".into()
    }
}

/// A markdown image link to a plot in the output folder.
pub fn image(alt: &str, file: &str) -> String {
    format!("![{alt}]({file})\n\n")
}

/// The whole report: title, how it was made, the conclusions, then each section.
pub fn report(sections: &[Section], header: &str) -> String {
    let mut s = String::from("# urto accuracy-cost report\n\n");
    let _ = writeln!(s, "{header}\n");
    s.push_str("## What to choose when (from the numbers below)\n\n");
    for sec in sections {
        for c in &sec.conclusions {
            let _ = writeln!(s, "- **{}**: {c}", sec.title);
        }
    }
    s.push('\n');
    for (i, sec) in sections.iter().enumerate() {
        let _ = write!(
            s,
            "## {}. {}\n\n{}\n",
            i + 1,
            sec.title,
            sec.body.trim_end()
        );
        s.push('\n');
    }
    s
}
