//! Whole numbers as users write them on a command line: a range (`1-5`) or a list (`1,3,5`).

/// A command-line list of whole numbers, written as a range (`1-5`) or a list (`1,3,5`):
/// sorted, each once, never empty.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NumberList(pub Vec<u64>);

impl NumberList {
    /// The longest range taken (longer ones are surely typing errors).
    const LONGEST: u64 = 100_000;

    /// Parses `text`; anything else than a range or list of whole numbers is a usage error.
    pub fn parse(text: &str) -> Result<Self, String> {
        let bad = || format!("expected a range like 1-5 or a list like 1,3,5, got {text:?}");
        let number = |t: &str| t.trim().parse::<u64>().map_err(|_| bad());
        let mut numbers: Vec<u64> = match text.split_once('-') {
            Some((a, b)) => {
                let (a, b) = (number(a)?, number(b)?);
                if b.saturating_sub(a) >= Self::LONGEST {
                    return Err(format!(
                        "{text:?} spans more than {} numbers",
                        Self::LONGEST
                    ));
                }
                (a..=b).collect()
            }
            None => text.split(',').map(number).collect::<Result<_, _>>()?,
        };
        if numbers.is_empty() {
            return Err(bad());
        }
        numbers.sort_unstable();
        numbers.dedup();
        Ok(Self(numbers))
    }
}

/// Solution depths written as a range or a list ("1-5", "6,8,10", "3"): sorted, each once, none
/// zero.
pub fn depths(text: &str) -> Result<Vec<usize>, String> {
    let bad =
        || format!("expected a range like 1-5 or a list like 1,3,5 of depths from 1, got {text:?}");
    let numbers = NumberList::parse(text).map_err(|_| bad())?.0;
    if numbers.contains(&0) {
        return Err(bad());
    }
    numbers
        .into_iter()
        .map(|d| usize::try_from(d).map_err(|_| bad()))
        .collect()
}

/// A command-line number that must be finite and positive (seconds, millimetres, spacings):
/// negative, zero, NaN and infinite values are usage errors (exit code 2), never a panic.
pub fn positive_finite(text: &str) -> Result<f64, String> {
    let value: f64 = text
        .parse()
        .map_err(|_| format!("{text:?} is not a number"))?;
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(format!("{text} must be a finite number above 0"))
    }
}

/// A command-line number that must be finite and not negative (a standard deviation).
pub fn non_negative_finite(text: &str) -> Result<f64, String> {
    let value: f64 = text
        .parse()
        .map_err(|_| format!("{text:?} is not a number"))?;
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(format!("{text} must be a finite number of at least 0"))
    }
}

/// A command-line probability: a number from 0 to 1 (NaN refused).
pub fn probability(text: &str) -> Result<f64, String> {
    let value: f64 = text
        .parse()
        .map_err(|_| format!("{text:?} is not a number"))?;
    if (0.0..=1.0).contains(&value) {
        Ok(value)
    } else {
        Err(format!("{text} must be a probability, from 0 to 1"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn number_lists_are_ranges_or_lists_sorted_once_each() {
        assert_eq!(NumberList::parse("1-3").unwrap().0, vec![1, 2, 3]);
        assert_eq!(NumberList::parse("4").unwrap().0, vec![4]);
        assert_eq!(NumberList::parse("5, 2,2").unwrap().0, vec![2, 5]);
        assert_eq!(NumberList::parse("0-0").unwrap().0, vec![0]);
        for bad in [
            "", "3-1", "a", "1,,2", "-3", "1-x", "1-2-3", "0-100000", "-1",
        ] {
            assert!(NumberList::parse(bad).is_err(), "{bad:?} was accepted");
        }
    }

    #[test]
    fn depths_are_a_range_or_a_list_sorted_once_each_and_never_zero() {
        assert_eq!(depths("1-5").unwrap(), vec![1, 2, 3, 4, 5]);
        assert_eq!(depths("6-6").unwrap(), vec![6]);
        assert_eq!(depths("5, 1,3,3").unwrap(), vec![1, 3, 5]);
        for bad in ["", "0-3", "0", "5-1", "a", "1,,2", "-3", "1-x"] {
            assert!(depths(bad).is_err(), "{bad:?} was accepted");
        }
    }
}
