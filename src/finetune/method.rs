//! The choice of minimiser for fine tuning's spring energies.

/// Which minimiser fine tuning uses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub enum FinetuneMethod {
    /// Levenberg-Marquardt on the sparse Gauss-Newton matrix
    /// ([`levenberg_marquardt`](crate::linalg::levenberg_marquardt)):
    /// tens of iterations. The default.
    #[default]
    LevenbergMarquardt,
    /// argmin's nonlinear conjugate gradient (Polak-Ribière+, Moré-Thuente
    /// line search), the method issue 8 named: thousands of iterations on
    /// the same problems.
    NonlinearCg,
}

impl std::str::FromStr for FinetuneMethod {
    type Err = crate::error::Error;
    /// `lm` or `ncg`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "lm" => Ok(FinetuneMethod::LevenbergMarquardt),
            "ncg" => Ok(FinetuneMethod::NonlinearCg),
            _ => Err(crate::error::Error::input(format!(
                "unknown method {s:?}: expected lm or ncg"
            ))),
        }
    }
}
