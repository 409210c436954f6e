//! CSV in (docs/FORMATS.md, "Importing a path"): one `x, y` pair a line,
//! as spreadsheets export it, decimal commas included.

use super::*;

/// Points of a CSV file as a trajectory (mm, centred on `o` as an SVG's).
pub fn csv_trajectory(text: &str) -> Result<Vec<[f64; 2]>> {
    csv_path(text).map(|p| p.points)
}

/// The fields of one CSV line. A line with `;` (a European spreadsheet's
/// export, `45,000;0,000`) or a tab between its fields may write its
/// numbers with a decimal comma; a line with neither is split at commas
/// and spaces, and one that mixes a decimal comma with spaces
/// (`45,5 0,2`: x 45.5 and y 0.2, or four numbers?) is refused by name
/// rather than read as a zig-zag.
pub(super) fn csv_fields(line: &str, key: &str) -> Result<Vec<String>> {
    let decimal_comma = |f: &str| f.trim().replace(',', ".");
    if line.contains(';') || line.contains('\t') {
        return Ok(line
            .split([';', '\t'])
            .map(decimal_comma)
            .filter(|f| !f.is_empty())
            .collect());
    }
    let b = line.as_bytes();
    let mixed = (1..b.len().saturating_sub(1))
        .any(|k| b[k] == b',' && b[k - 1].is_ascii_digit() && b[k + 1].is_ascii_digit())
        && line.split(',').any(|part| part.trim().contains(' '));
    if mixed {
        return Err(Error::invalid(
            key,
            format!("`{line}` mixes a decimal comma with spaces between fields: separate x and y by `;` or a tab (`45,5; 0,2`), or write decimal points"),
        ));
    }
    Ok(line
        .split([',', ' '])
        .map(str::trim)
        .filter(|f| !f.is_empty())
        .map(str::to_string)
        .collect())
}

/// [`csv_trajectory`], closed when its last point meets its first.
pub fn csv_path(text: &str) -> Result<ImportedPath> {
    let mut pts = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let key = format!("csv line {}", i + 1);
        let fields = csv_fields(line, &key)?;
        let parsed: Vec<Option<f64>> = fields.iter().map(|f| f.parse().ok()).collect();
        if pts.is_empty() && parsed.iter().all(Option::is_none) {
            continue; // a header (or a title) before the data
        }
        if fields.len() < 2 {
            return Err(Error::invalid(
                key,
                format!("expected `x, y`, got `{line}`"),
            ));
        }
        let mut xy = [0.0; 2];
        for k in 0..2 {
            xy[k] = parsed[k]
                .filter(|v: &f64| v.is_finite())
                .ok_or_else(|| Error::invalid(&key, format!("`{}` is not a number", fields[k])))?;
        }
        pts.push(xy);
    }
    let closed = pts.len() > 3
        && pts
            .first()
            .zip(pts.last())
            .is_some_and(|(a, b)| (a[0] - b[0]).hypot(a[1] - b[1]) <= 1e-6);
    let mut path = finish_path(pts, closed, "csv")?;
    // Centred on o, as an SVG is: a CSV from a drawing starting at (0, 0)
    // would otherwise land on the centre.
    centre(&mut path.points);
    Ok(path)
}
