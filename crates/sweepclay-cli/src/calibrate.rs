//! `sweepclay calibrate`: write the clay calibration print, then turn the
//! walls measured on it into the printer's `e_per_mm3` and save it
//! (docs/CALIBRATION.md). A thin shell over `sweepclay_core::calibrate`.

use crate::{load_printer, say, write_atomic};
use anyhow::{bail, Context, Result};
use clap::Args;
use std::path::PathBuf;
use sweepclay_core::calibrate::{self, TRUST_SPREAD};
use sweepclay_core::design::Params;

#[derive(Args, Debug)]
pub struct CalibrateArgs {
    /// Printer preset or printer JSON file to calibrate.
    #[arg(long)]
    printer: String,
    /// Where to write the calibration print.
    #[arg(short, long, default_value = "calibration.gcode")]
    output: PathBuf,
    /// The wall thickness measured at each band (mm), lowest band first,
    /// comma-separated: computes E per mm³ and saves it.
    #[arg(long, value_delimiter = ',', num_args = 1..)]
    measured: Option<Vec<f64>>,
    /// The calibration print the walls were measured on, for the E it was
    /// written with [default: the -o file, if it is there].
    #[arg(long, value_name = "FILE")]
    print: Option<PathBuf>,
    /// Where to save the calibrated profile [default: the --printer file
    /// itself; a preset needs --save].
    #[arg(long)]
    save: Option<PathBuf>,
    /// Layer height of the print (mm) [default: 1.25].
    #[arg(long)]
    layer_height: Option<f64>,
    /// Narrowest band's bead (mm) [default: 3].
    #[arg(long)]
    width_min: Option<f64>,
    /// Widest band's bead (mm) [default: 6].
    #[arg(long)]
    width_max: Option<f64>,
}

fn params(a: &CalibrateArgs) -> Params {
    let d = Params::default();
    Params {
        layer_height: a.layer_height.unwrap_or(d.layer_height),
        width_min: a.width_min.unwrap_or(d.width_min),
        width_max: a.width_max.unwrap_or(d.width_max),
        ..d
    }
}

pub fn run(a: CalibrateArgs) -> Result<i32> {
    let printer = load_printer(&a.printer)?;
    let params = params(&a);
    let print = calibrate::print(&printer, &params).map_err(|e| anyhow::anyhow!("{e}"))?;
    let Some(measured) = &a.measured else {
        // Never hand the potter a print that would not print.
        let report = sweepclay_check::check(&print.gcode, &sweepclay_plan::printer_check(&printer));
        if !report.printable {
            bail!(
                "the calibration print for `{}` does not pass the check: {}",
                printer.name,
                report.render().lines().next().unwrap_or("")
            );
        }
        crate::files::not_an_input("-o", &a.output, &[std::path::Path::new(&a.printer)])?;
        write_atomic(&a.output, print.gcode.as_bytes())?;
        say(format_args!(
            "wrote      {} ({} bands, checked: printable, {:.0} ml of clay)\n",
            a.output.display(),
            print.bands.len(),
            report.volume_ml
        ))?;
        for (i, b) in print.bands.iter().enumerate() {
            say(format_args!(
                "band {}     {:>5.1}–{:<5.1} mm high: written {:.2} mm thick\n",
                i + 1,
                b.z[0],
                b.z[1],
                b.width_mm
            ))?;
        }
        say(format_args!(
            "next       print it, let it firm up, measure the wall at each band's middle with a calliper, then:\n           sweepclay calibrate --printer {} --measured T1,T2,T3,T4\n",
            a.printer
        ))?;
        return Ok(0);
    };
    // The E the print was written with travels with the print: the
    // profile's may have changed since (a first calibration saved), and
    // fitting against it would compound (docs/CALIBRATION.md).
    let print_file = a
        .print
        .clone()
        .or_else(|| a.output.is_file().then(|| a.output.clone()));
    let e_written = match &print_file {
        Some(f) => {
            let text = crate::read_capped(f, 1 << 20)
                .map(|b| String::from_utf8_lossy(&b).into_owned())
                .map_err(|e| anyhow::anyhow!("--print: {e}"))?;
            let (e, widths) = calibrate::written(&text).with_context(|| {
                format!(
                    "--print {}: not a calibration print sweepclay wrote",
                    f.display()
                )
            })?;
            let now: Vec<f64> = print.bands.iter().map(|b| b.width_mm).collect();
            if widths.len() != now.len()
                || widths.iter().zip(&now).any(|(w, n)| (w - n).abs() > 1e-3)
            {
                bail!(
                    "--print {}: written with bands {widths:?} mm wide, but these settings give {now:?}: give the --layer-height, --width-min and --width-max it was written with",
                    f.display()
                );
            }
            say(format_args!(
                "print      {} was written with E per mm³ {e}\n",
                f.display()
            ))?;
            e
        }
        None => {
            eprintln!("note: no calibration print to read (--print FILE): taking the E per mm³ the printer has now, {}, as the one it was written with", printer.e_per_mm3);
            printer.e_per_mm3
        }
    };
    let fit =
        calibrate::fit(&print.bands, measured, e_written).map_err(|e| anyhow::anyhow!("--{e}"))?;
    for (i, (t, b)) in measured.iter().zip(&print.bands).enumerate() {
        say(format_args!(
            "band {}     written {:.2} mm, measured {:.2} mm: {:.4} E/mm³\n",
            i + 1,
            b.width_mm,
            t,
            fit.per_band[i]
        ))?;
    }
    say(format_args!(
        "e_per_mm3  {:.5} (was {:.5}; the bands agree within {:.1} %)\n",
        fit.e_per_mm3,
        printer.e_per_mm3,
        fit.spread * 100.0
    ))?;
    if fit.spread > TRUST_SPREAD {
        bail!(
            "the bands disagree by {:.0} % (more than {:.0} %): measure again at each band's middle, or print the calibration again; nothing saved",
            fit.spread * 100.0,
            TRUST_SPREAD * 100.0
        );
    }
    let target = match (&a.save, std::path::Path::new(&a.printer).is_file()) {
        (Some(p), _) => p.clone(),
        (None, true) => PathBuf::from(&a.printer),
        (None, false) => bail!(
            "`{}` is a preset: name a file to save the calibrated profile in with --save my-printer.json",
            a.printer
        ),
    };
    // The profile as written, with only e_per_mm3 changed; a preset is
    // written whole.
    let mut profile = if std::path::Path::new(&a.printer).is_file() {
        let text = std::fs::read_to_string(&a.printer).with_context(|| a.printer.clone())?;
        serde_json::from_str::<serde_json::Value>(&text).with_context(|| a.printer.clone())?
    } else {
        serde_json::to_value(&printer)?
    };
    let obj = profile
        .as_object_mut()
        .with_context(|| format!("{}: not a printer object", a.printer))?;
    obj.insert(
        "e_per_mm3".into(),
        serde_json::json!((fit.e_per_mm3 * 1e6).round() / 1e6),
    );
    write_atomic(
        &target,
        format!("{}\n", serde_json::to_string_pretty(&profile)?).as_bytes(),
    )?;
    say(format_args!("saved      {}\n", target.display()))?;
    Ok(0)
}
