//! How a message shows a number someone gave (a form's stroke, a set-point, an option):
//! short whatever its size, so that `1e308` reads as `1e308` and not as 309 digits that push
//! the reason off the line.
//!
//! This crate is the lowest one whose messages echo numbers from files (its form
//! descriptions); `dressform` (`messages::number`) and the simulator use this one formatter.

use std::fmt::{self, Display};

/// A number as a message shows it: up to 6 significant digits, in exponent form when very
/// large or small (`1e300`, `-3.2e-12`, not hundreds of digits).
pub fn number(x: f64) -> Number {
    Number(x)
}

/// See [`number`].
#[derive(Debug, Clone, Copy)]
pub struct Number(pub f64);

impl Display for Number {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let x = self.0;
        // Plain notation covers body sizes in any unit, from 0.001 mm to 10 km.
        if x == 0.0 || !x.is_finite() || (1e-3..1e7).contains(&x.abs()) {
            let digits = 5usize.saturating_sub(x.abs().log10().floor().max(0.0) as usize);
            let s = format!("{x:.digits$}");
            let s =
                if s.contains('.') { s.trim_end_matches('0').trim_end_matches('.') } else { &s };
            f.write_str(if s == "-0" { "0" } else { s })
        } else {
            let s = format!("{x:.5e}");
            let (mantissa, exponent) = s.split_once('e').unwrap_or((&s, "0"));
            let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
            write!(f, "{mantissa}e{exponent}")
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_short() {
        let shown: Vec<String> = [
            0.0,
            -0.0,
            1.7,
            1700.0,
            1234.56789,
            0.0125,
            1e300,
            -2.5e-9,
            1e7,
            1e308,
            -3.2e-12,
            f64::MAX,
            5e-324,
            655.34,
            9_999_999.7,
        ]
        .map(|x| number(x).to_string())
        .into();
        assert_eq!(
            shown,
            [
                "0",
                "0",
                "1.7",
                "1700",
                "1234.57",
                "0.0125",
                "1e300",
                "-2.5e-9",
                "1e7",
                "1e308",
                "-3.2e-12",
                "1.79769e308",
                "4.94066e-324",
                "655.34",
                "10000000"
            ]
        );
        assert_eq!(number(f64::NAN).to_string(), "NaN");
        assert_eq!(number(f64::NEG_INFINITY).to_string(), "-inf");
    }
}
