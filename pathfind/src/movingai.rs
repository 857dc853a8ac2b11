//! Moving AI grid benchmark files (Sturtevant 2012): `.map` grids and `.map.scen` scenarios.

use std::fmt::Write as _;
use std::path::Path;

use slam_core::{BitGrid, Cell};

use crate::error::PathfindError;

/// A Moving AI map: the grid (cell (x, y) is column x, row y counted from the top, as in the
/// file) and the raw terrain letters.
#[derive(Clone, Debug)]
pub struct MovingAiMap {
    /// Blocked cells are every letter but `.`, `G` and `S` (the benchmark's strict rule).
    pub grid: BitGrid,
    /// The terrain letter of each cell, row by row.
    pub terrain: Vec<u8>,
}

/// Whether a terrain letter is traversable: `.` (ground), `G` (grass) and `S` (swamp). `W`
/// (water, passable only from water), `T` (trees), `@` and `O` (out of bounds) are blocked.
#[must_use]
pub fn is_passable(letter: u8) -> bool {
    matches!(letter, b'.' | b'G' | b'S')
}

fn parse_err(line: usize, message: impl Into<String>) -> PathfindError {
    PathfindError::Parse {
        line,
        message: message.into(),
    }
}

fn read_text(path: &Path) -> Result<String, PathfindError> {
    std::fs::read_to_string(path).map_err(|source| PathfindError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// Parse a `.map` file.
///
/// # Errors
/// [`PathfindError::Parse`] with the line number for a bad header, a header whose size the
/// text after it cannot hold (checked before anything is allocated), a row of the wrong length,
/// too few rows or an unknown letter; [`PathfindError::Grid`] past [`slam_core::MAX_GRID_CELLS`].
pub fn parse_map(text: &str) -> Result<MovingAiMap, PathfindError> {
    let (mut width, mut height) = (None, None);
    // The text after the line read last, and that line's 1-based number.
    let mut rest = text;
    let mut header_lines = 0;
    loop {
        if rest.is_empty() {
            return Err(parse_err(0, "no 'map' line"));
        }
        let (line, tail) = rest.split_once('\n').unwrap_or((rest, ""));
        rest = tail;
        header_lines += 1;
        let k = header_lines - 1;
        let mut words = line.split_whitespace();
        match (words.next(), words.next()) {
            (Some("type"), Some(_)) | (None, _) => {}
            (Some("height"), Some(v)) => {
                height = Some(
                    v.parse::<u32>()
                        .map_err(|_| parse_err(k + 1, format!("height {v:?}")))?,
                );
            }
            (Some("width"), Some(v)) => {
                width = Some(
                    v.parse::<u32>()
                        .map_err(|_| parse_err(k + 1, format!("width {v:?}")))?,
                );
            }
            (Some("map"), None) => break,
            _ => return Err(parse_err(k + 1, format!("unexpected header line {line:?}"))),
        }
    }
    let width = width.ok_or_else(|| parse_err(0, "no width line"))?;
    let height = height.ok_or_else(|| parse_err(0, "no height line"))?;
    // One letter per cell must follow: allocate for the map only once the text can hold it.
    let cells = u64::from(width) * u64::from(height);
    if cells > rest.len() as u64 {
        return Err(parse_err(
            header_lines,
            format!(
                "the header states {width}x{height} = {cells} cells but only {} bytes follow",
                rest.len()
            ),
        ));
    }
    let mut lines = rest
        .lines()
        .enumerate()
        .map(|(k, line)| (k + header_lines, line));
    let mut grid = BitGrid::new(width, height)?;
    let mut terrain = Vec::with_capacity(width as usize * height as usize);
    for y in 0..height {
        let (k, line) = lines
            .next()
            .ok_or_else(|| parse_err(0, format!("only {y} of {height} rows")))?;
        let row = line.trim_end_matches('\r').as_bytes();
        if row.len() != width as usize {
            return Err(parse_err(
                k + 1,
                format!("row of {} letters, width is {width}", row.len()),
            ));
        }
        for (x, &letter) in row.iter().enumerate() {
            if !matches!(letter, b'.' | b'G' | b'S' | b'W' | b'T' | b'@' | b'O') {
                return Err(parse_err(
                    k + 1,
                    format!("unknown terrain letter {:?}", letter as char),
                ));
            }
            if !is_passable(letter) {
                grid.set(Cell::new(x as u32, y), true)?;
            }
        }
        terrain.extend_from_slice(row);
    }
    Ok(MovingAiMap { grid, terrain })
}

/// Read a `.map` file.
///
/// # Errors
/// [`PathfindError::Io`] or as [`parse_map`].
pub fn read_map(path: impl AsRef<Path>) -> Result<MovingAiMap, PathfindError> {
    parse_map(&read_text(path.as_ref())?)
}

/// The `.map` text of `map` (octile type, the terrain letters row by row): reads back to the
/// same grid and letters.
#[must_use]
pub fn map_text(map: &MovingAiMap) -> String {
    let (w, h) = (map.grid.width(), map.grid.height());
    let mut s = format!("type octile\nheight {h}\nwidth {w}\nmap\n");
    s.reserve(map.terrain.len() + h as usize);
    for row in map.terrain.chunks(w as usize) {
        s.extend(row.iter().map(|&b| char::from(b)));
        s.push('\n');
    }
    s
}

/// One benchmark query.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Scenario {
    /// Difficulty bucket (about a quarter of the optimal length).
    pub bucket: u32,
    /// The map column as written (not reliable as a path; resolve maps yourself).
    pub map: String,
    /// Map width the scenario was made for.
    pub map_width: u32,
    /// Map height the scenario was made for.
    pub map_height: u32,
    /// Start cell.
    pub start: Cell,
    /// Goal cell.
    pub goal: Cell,
    /// The published optimal length.
    pub optimal_length: f64,
    /// How far a computed length may differ from `optimal_length`: 1e-4, or the precision the
    /// file printed the length with when coarser (6 significant digits in `version 1` files, two
    /// decimals in `version 1.0` files).
    pub tolerance: f64,
}

/// Parse a `.scen` file (`version 1` or `version 1.0`, tabs or spaces).
///
/// # Errors
/// [`PathfindError::Parse`] with the line number.
pub fn parse_scenarios(text: &str) -> Result<Vec<Scenario>, PathfindError> {
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let (_, first) = lines
        .next()
        .ok_or_else(|| parse_err(1, "empty scenario file"))?;
    let two_decimals = match first.split_whitespace().collect::<Vec<_>>().as_slice() {
        ["version", "1"] => false,
        ["version", "1.0"] => true,
        _ => return Err(parse_err(1, format!("unknown header {first:?}"))),
    };
    let mut out = Vec::new();
    for (k, line) in lines {
        let f: Vec<&str> = line.split_whitespace().collect();
        if f.len() != 9 {
            return Err(parse_err(k + 1, format!("{} fields, 9 expected", f.len())));
        }
        let num = |i: usize| -> Result<u32, PathfindError> {
            f[i].parse::<u32>().map_err(|_| {
                parse_err(
                    k + 1,
                    format!("field {} {:?} is not a whole number", i + 1, f[i]),
                )
            })
        };
        let optimal_length = f[8]
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite() && *v >= 0.0)
            .ok_or_else(|| parse_err(k + 1, format!("length {:?}", f[8])))?;
        let printed = if two_decimals {
            0.005 + 1e-9
        } else if optimal_length > 0.0 {
            10f64.powf(optimal_length.log10().floor() - 5.0)
        } else {
            0.0
        };
        out.push(Scenario {
            bucket: num(0)?,
            map: f[1].to_string(),
            map_width: num(2)?,
            map_height: num(3)?,
            start: Cell::new(num(4)?, num(5)?),
            goal: Cell::new(num(6)?, num(7)?),
            optimal_length,
            tolerance: printed.max(1e-4),
        });
    }
    Ok(out)
}

/// The `.scen` text of `scenarios` (`version 1`, tab-separated, lengths printed so they read
/// back exactly). Each read-back tolerance is that of a `version 1` file.
#[must_use]
pub fn scenarios_text(scenarios: &[Scenario]) -> String {
    let mut s = String::from("version 1\n");
    for q in scenarios {
        let _ = writeln!(
            s,
            "{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\t{:?}",
            q.bucket,
            q.map,
            q.map_width,
            q.map_height,
            q.start.x,
            q.start.y,
            q.goal.x,
            q.goal.y,
            q.optimal_length
        );
    }
    s
}

/// Read a `.scen` file.
///
/// # Errors
/// [`PathfindError::Io`] or as [`parse_scenarios`].
pub fn read_scenarios(path: impl AsRef<Path>) -> Result<Vec<Scenario>, PathfindError> {
    parse_scenarios(&read_text(path.as_ref())?)
}
