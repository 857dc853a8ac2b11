//! Command-line pieces more than one example takes: the SLAM backend choice, comma-separated
//! numbers (a goal `X,Y`, an initial pose), and the command-line name of a backend choice.
//!
//! The parsers return `Result<_, String>` so that `clap` can use them as value parsers
//! (`#[arg(value_parser = parse_goal)]`) and report a bad value with the option's name.

use clap::ValueEnum;
use nalgebra::Vector2;

/// The registration backend of the SLAM engine (odometry against the local map, and loop
/// refinement), as `--registration` chooses it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Registration {
    /// Point-to-plane ICP odometry and loop refinement.
    #[value(name = "p2plane")]
    PointToPlane,
    /// LOAM edge and planar features for odometry and loop refinement.
    #[value(name = "loam")]
    Loam,
}

/// `N` comma-separated numbers, e.g. `parse_numbers::<2>("1.5,-2")`.
///
/// # Errors
/// A message naming the count when there are not `N` fields, or the field that is not a finite
/// number.
pub fn parse_numbers<const N: usize>(text: &str) -> Result<[f64; N], String> {
    let values: Vec<f64> = text
        .split(',')
        .map(|field| field.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|e| format!("{e} (expected {N} comma-separated numbers)"))?;
    if let Some(bad) = values.iter().find(|v| !v.is_finite()) {
        return Err(format!("{bad} is not a finite number"));
    }
    <[f64; N]>::try_from(values.as_slice()).map_err(|_| {
        format!(
            "expected {N} comma-separated numbers, found {}",
            values.len()
        )
    })
}

/// A goal `X,Y` (metres), as `--goal` takes it.
///
/// # Errors
/// As [`parse_numbers`].
pub fn parse_goal(text: &str) -> Result<Vector2<f64>, String> {
    parse_numbers::<2>(text).map(Vector2::from)
}

/// The name by which the command line gives `value` (e.g. `p2plane`), for output lines.
#[must_use]
pub fn value_name<T: ValueEnum>(value: &T) -> String {
    value
        .to_possible_value()
        .map_or_else(String::new, |v| v.get_name().to_owned())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_and_goals() {
        assert_eq!(parse_numbers::<3>("1, -2.5,3e1"), Ok([1.0, -2.5, 30.0]));
        assert_eq!(parse_goal("-3.5,2"), Ok(Vector2::new(-3.5, 2.0)));
        assert!(parse_goal("1").unwrap_err().contains("found 1"));
        assert!(parse_goal("1,2,3").unwrap_err().contains("found 3"));
        assert!(parse_goal("1,x").unwrap_err().contains("expected 2"));
        assert!(parse_goal("").is_err());
    }

    #[test]
    fn names_as_on_the_command_line() {
        assert_eq!(value_name(&Registration::PointToPlane), "p2plane");
        assert_eq!(value_name(&Registration::Loam), "loam");
    }
}
