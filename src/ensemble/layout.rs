//! Which second moments of the stacked residuals ρ = (r(t_0), r(t_1), …) an
//! ensemble keeps: every pair of components (a packed lower triangle, O(fixes²)), or the pairs
//! whose fixes are at most `max_lag` fixes apart (a band, O(fixes·lag)).
//!
//! Either way row a of the lower triangle keeps a contiguous run of columns ending at the
//! diagonal, [first_col(a), a], stored row after row.

use crate::state::ErrorState;

/// The stored part of the lower triangle of Σ ρ·ρᵀ; component a of ρ is component a mod w of
/// the residual at fix ⌊a / w⌋, w the residual's width.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ResidualLayout {
    fixes: usize,
    /// Components of one residual, w.
    width: usize,
    max_lag: Option<usize>,
    /// Start of every row in the packed storage, and the total length last.
    row_start: Vec<usize>,
}

impl ResidualLayout {
    /// The layout of the error state's GPS residuals for `fixes` fixes keeping pairs at most
    /// `max_lag` fixes apart (`None`: all).
    pub fn new(fixes: usize, max_lag: Option<usize>) -> Self {
        Self::with_width(fixes, ErrorState::MEAS, max_lag)
    }

    /// The layout for `fixes` residuals of `width` components each, keeping pairs at most
    /// `max_lag` fixes apart (`None`: all).
    pub fn with_width(fixes: usize, width: usize, max_lag: Option<usize>) -> Self {
        // A lag that reaches every pair is no band at all.
        let max_lag = max_lag.filter(|&l| l + 1 < fixes);
        let mut row_start = Vec::with_capacity(width * fixes + 1);
        let mut start = 0;
        for a in 0..width * fixes {
            row_start.push(start);
            start += a + 1 - first_col(a, width, max_lag);
        }
        row_start.push(start);
        Self {
            fixes,
            width,
            max_lag,
            row_start,
        }
    }

    /// Components of one residual.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Number of fixes.
    pub fn fixes(&self) -> usize {
        self.fixes
    }

    /// The largest lag kept, in fixes; `None` when every pair is kept.
    pub fn max_lag(&self) -> Option<usize> {
        self.max_lag
    }

    /// The first column kept in row a.
    #[inline]
    pub fn first_col(&self, a: usize) -> usize {
        first_col(a, self.width, self.max_lag)
    }

    /// Number of stored products.
    pub fn len(&self) -> usize {
        *self
            .row_start
            .last()
            .expect("a row start per row and the end")
    }

    /// Whether nothing is stored (no fixes).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Where row a's first kept column is stored.
    #[inline]
    pub fn row_start(&self, a: usize) -> usize {
        self.row_start[a]
    }

    /// Where the product of components a and b is stored, if it is.
    #[inline]
    pub fn index(&self, a: usize, b: usize) -> Option<usize> {
        let (hi, lo) = if a >= b { (a, b) } else { (b, a) };
        let first = self.first_col(hi);
        (hi < self.width * self.fixes && lo >= first).then(|| self.row_start[hi] + lo - first)
    }

    /// Whether fixes `later` and `earlier` are a kept pair.
    pub fn keeps(&self, later: usize, earlier: usize) -> bool {
        self.max_lag.is_none_or(|l| later - earlier <= l)
    }
}

#[inline]
fn first_col(a: usize, width: usize, max_lag: Option<usize>) -> usize {
    match max_lag {
        None => 0,
        Some(l) => width * (a / width).saturating_sub(l),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_full_layout_is_the_packed_triangle() {
        let l = ResidualLayout::new(5, None);
        assert_eq!(l.len(), 10 * 11 / 2);
        assert_eq!(l.index(4, 2), Some(4 * 5 / 2 + 2));
        assert_eq!(l.index(2, 4), l.index(4, 2));
        // A lag reaching every pair is the full triangle too.
        assert_eq!(ResidualLayout::new(5, Some(4)), l);
    }

    #[test]
    fn a_band_keeps_pairs_within_its_lag_only() {
        let l = ResidualLayout::new(6, Some(1));
        // Fix 3 (rows 6, 7) keeps fixes 2 and 3 (columns 4..=row).
        assert_eq!(l.first_col(7), 4);
        assert!(l.index(7, 4).is_some() && l.index(7, 3).is_none());
        assert!(l.keeps(3, 2) && !l.keeps(3, 1));
        // Every stored index is distinct and in range.
        let mut seen = vec![false; l.len()];
        for a in 0..12 {
            for b in l.first_col(a)..=a {
                let i = l.index(a, b).unwrap();
                assert!(!seen[i]);
                seen[i] = true;
            }
        }
        assert!(seen.into_iter().all(|s| s));
    }
}
