//! `sweepclay check`: any G-code file judged by `sweepclay-check`
//! (docs/CHECKER.md), with the printer it was made for.

use super::*;

#[derive(Args, Debug)]
pub(crate) struct CheckArgs {
    /// G-code file to check.
    pub(crate) file: PathBuf,
    /// Printer preset or printer JSON file (build volume, bed_min,
    /// e_per_mm3, nozzle_radius) [default: the printer in a sweepclay
    /// file's header, else generic].
    #[arg(long)]
    pub(crate) printer: Option<String>,
    /// Whose reading of the G-code to follow where firmwares differ
    /// (G90/G91 and E; numbers such as Z5e-05): marlin, klipper or reprap.
    #[arg(long, default_value = "marlin")]
    pub(crate) firmware: sweepclay_check::Firmware,
    /// H: extruder body height above the nozzle tip (mm) [default: 30].
    #[arg(long)]
    pub(crate) nozzle_height: Option<f64>,
    /// Narrowest expected bead (mm) [default: 3].
    #[arg(long)]
    pub(crate) width_min: Option<f64>,
    /// Widest expected bead (mm) [default: 6].
    #[arg(long)]
    pub(crate) width_max: Option<f64>,
    /// Target overlap with the bead below (fraction); beads under it are
    /// counted [default: 0.6667].
    #[arg(long)]
    pub(crate) overlap: Option<f64>,
    /// Overlap under which a bead fails (fraction) [default: 0.5].
    #[arg(long)]
    pub(crate) min_overlap: Option<f64>,
    /// Overhang threshold from vertical (degrees) [default: 57].
    #[arg(long)]
    pub(crate) max_overhang_deg: Option<f64>,
    /// The print's first bead must start at most this high (mm) [default: 3].
    #[arg(long)]
    pub(crate) first_layer_max: Option<f64>,
    /// Print the report as JSON.
    #[arg(long)]
    pub(crate) json: bool,
}

/// The flag that sets a field of the check's configuration, for messages.
pub(crate) fn check_flag(field: &str) -> String {
    match field {
        "nozzle_height" => "--nozzle-height".into(),
        "width_min" => "--width-min".into(),
        "width_max" => "--width-max".into(),
        "overlap_target" => "--overlap".into(),
        "overlap_min" => "--min-overlap".into(),
        "max_overhang_deg" => "--max-overhang-deg".into(),
        "first_layer_max_mm" => "--first-layer-max".into(),
        other => format!("the printer's `{other}`"),
    }
}

/// The check's configuration for `file`: the printer named, else the one
/// a sweepclay file's header names, else generic.
pub(crate) fn base_check_config(file: &Path, printer: Option<&str>) -> Result<CheckConfig> {
    let open = || std::fs::File::open(file).with_context(|| format!("reading {}", file.display()));
    Ok(match printer {
        Some(name) => {
            let p = load_printer(name)?;
            CheckConfig {
                printer: format!("{} (--printer)", p.name),
                ..printer_check(&p)
            }
        }
        None => {
            // Our own files name their printer and parameters in the header.
            use std::io::{BufRead, Read};
            let mut head = String::new();
            for line in std::io::BufReader::new(open()?.take(1 << 16))
                .lines()
                .take(sweepclay_check::header::HEADER_LINES)
            {
                let Ok(line) = line else { break };
                head.push_str(&line);
                head.push('\n');
            }
            sweepclay_check::header::config_from_header(&head, &CheckConfig::default())
                .unwrap_or_else(|| CheckConfig {
                    printer:
                        "generic (assumed: the file names no sweepclay printer; pass --printer)"
                            .into(),
                    ..CheckConfig::default()
                })
        }
    })
}

pub(crate) fn check_cmd(a: CheckArgs) -> Result<i32> {
    let open =
        || std::fs::File::open(&a.file).with_context(|| format!("reading {}", a.file.display()));
    let base = base_check_config(&a.file, a.printer.as_deref())?;
    let cfg = CheckConfig {
        firmware: a.firmware,
        nozzle_height: a.nozzle_height.unwrap_or(base.nozzle_height),
        width_min: a.width_min.unwrap_or(base.width_min),
        width_max: a.width_max.unwrap_or(base.width_max),
        overlap_target: a.overlap.unwrap_or(base.overlap_target),
        overlap_min: a.min_overlap.unwrap_or(base.overlap_min),
        max_overhang_deg: a.max_overhang_deg.unwrap_or(base.max_overhang_deg),
        first_layer_max_mm: a.first_layer_max.unwrap_or(base.first_layer_max_mm),
        ..base
    };
    cfg.validate()
        .map_err(|e| anyhow::anyhow!("{}: {}", check_flag(e.field), e.reason))?;
    let report = check_reader(std::io::BufReader::with_capacity(1 << 16, open()?), &cfg)
        .with_context(|| format!("reading {}", a.file.display()))?;
    if a.json {
        say!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        say(format_args!("{}", report.render()))?;
    }
    Ok(if report.cannot_judge.is_some() {
        3
    } else if report.printable {
        0
    } else {
        1
    })
}
