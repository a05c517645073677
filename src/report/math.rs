//! LaTeX to MathML, for the report's equations.

use math_core::{LatexToMathML, MathCoreConfig, MathDisplay};

/// Converts LaTeX snippets to MathML Core (no namespace attribute: the report is HTML).
pub struct Math {
    converter: LatexToMathML,
}

impl Default for Math {
    fn default() -> Self {
        Self::new()
    }
}

impl Math {
    /// A converter with the report's macros: `\dx`, `\dxhat`, `\dxbar` (the a priori estimate δx̂⁻) and `\T` (transpose).
    pub fn new() -> Self {
        let config = MathCoreConfig {
            macros: vec![
                ("dx".into(), r"\delta\mathbf{x}".into()),
                ("dxhat".into(), r"\widehat{\delta\mathbf{x}}".into()),
                ("dxbar".into(), r"\widehat{\delta\mathbf{x}}^{-}".into()),
                ("T".into(), r"^{\mathsf{T}}".into()),
            ],
            ..Default::default()
        };
        Self {
            converter: LatexToMathML::new(config).expect("the report's macros parse"),
        }
    }

    fn convert(&self, latex: &str, display: MathDisplay) -> String {
        match self.converter.convert_with_local_state(latex, display) {
            Ok(r) => r.mathml,
            // The report's LaTeX is ours; a snippet that does not convert is a bug, shown visibly.
            Err(e) => panic!("LaTeX {latex:?} does not convert: {e:?}"),
        }
    }

    /// Inline MathML.
    pub fn inline(&self, latex: &str) -> String {
        self.convert(latex, MathDisplay::Inline)
    }

    /// Display (block) MathML.
    pub fn block(&self, latex: &str) -> String {
        self.convert(latex, MathDisplay::Block)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn converts_matrices_and_macros() {
        let m = Math::new();
        let out = m.block(r"\dx_{j+1} = \begin{bmatrix} 1 & \Delta t \\ 0 & 1 \end{bmatrix} \dx_j");
        assert!(out.starts_with("<math") && out.contains("<mtable"), "{out}");
        assert!(!out.contains("http"), "no namespace URL in HTML: {out}");
        let out = m.inline(r"\dxhat\T");
        assert!(out.contains("<mi") && out.contains('δ'), "{out}");
    }
}
