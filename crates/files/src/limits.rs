//! Limits given as numbers by a user: a time limit in seconds, read once, the same way by the
//! command line and by Python.

use crate::Error;
use std::time::Duration;

/// A time limit of `value` seconds (the option or argument `what`, for the message): `None`
/// for no limit (`inf`, or a limit beyond what a clock counts, such as 1e19 s).
///
/// # Errors
/// [`Error::Usage`] for NaN, zero or a negative number.
pub fn seconds(value: f64, what: &str) -> Result<Option<Duration>, Error> {
    if !(value > 0.0) {
        return Err(Error::Usage(format!(
            "{what} {value} is not a positive number of seconds (inf for no limit)"
        )));
    }
    // a limit no clock reaches is no limit: a deadline past the end of `Instant` would overflow
    Ok(Duration::try_from_secs_f64(value)
        .ok()
        .filter(|d| std::time::Instant::now().checked_add(*d).is_some()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_are_positive_seconds_or_none() {
        assert_eq!(seconds(1.5, "t").unwrap(), Some(Duration::from_millis(1500)));
        assert_eq!(seconds(f64::INFINITY, "t").unwrap(), None);
        assert_eq!(seconds(1e19, "t").unwrap(), None);
        assert_eq!(seconds(f64::MAX, "t").unwrap(), None);
        for bad in [f64::NAN, 0.0, -1.0, f64::NEG_INFINITY, -0.0] {
            let e = seconds(bad, "--time-limit").unwrap_err().to_string();
            assert!(
                e.contains("--time-limit") && e.contains("not a positive number"),
                "{bad}: {e}"
            );
        }
    }
}
