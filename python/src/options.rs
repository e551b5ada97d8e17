//! Keyword options of `fit` and `recover`, named as the CLI's flags in
//! snake_case (`--tol-stat` is `tol_stat`); an unknown name or a value of
//! the wrong type is a `ValueError` that lists what is accepted.

use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::arrays::value_error;

/// The options of one call, checked against the names it accepts.
pub struct Options<'a, 'py> {
    dict: Option<&'a Bound<'py, PyDict>>,
    function: &'static str,
}

impl<'a, 'py> Options<'a, 'py> {
    /// Checks that every key of `dict` is one of `known`.
    pub fn new(
        dict: Option<&'a Bound<'py, PyDict>>,
        function: &'static str,
        known: &[&str],
    ) -> PyResult<Self> {
        if let Some(d) = dict {
            for key in d.keys() {
                let name: String = key.extract()?;
                if !known.contains(&name.as_str()) {
                    return Err(value_error(format!(
                        "{function}: unknown option '{name}'; the options are {}",
                        known.join(", ")
                    )));
                }
            }
        }
        Ok(Options { dict, function })
    }

    fn get<T>(&self, name: &str, what: &str) -> PyResult<Option<T>>
    where
        T: pyo3::conversion::FromPyObjectOwned<'py>,
    {
        let Some(d) = self.dict else { return Ok(None) };
        match d.get_item(name)? {
            None => Ok(None),
            Some(v) if v.is_none() => Ok(None),
            Some(v) => v.extract::<T>().map(Some).map_err(|_| {
                value_error(format!(
                    "{}: option {name}={} is not {what}",
                    self.function,
                    v.repr().map(|r| r.to_string()).unwrap_or_default()
                ))
            }),
        }
    }

    /// A number, or `default`.
    pub fn f64(&self, name: &str, default: f64) -> PyResult<f64> {
        Ok(self.get(name, "a number")?.unwrap_or(default))
    }

    /// An optional number.
    pub fn opt_f64(&self, name: &str) -> PyResult<Option<f64>> {
        self.get(name, "a number")
    }

    /// A non-negative integer, or `default`.
    pub fn usize(&self, name: &str, default: usize) -> PyResult<usize> {
        Ok(self.get(name, "a non-negative integer")?.unwrap_or(default))
    }

    /// An optional non-negative integer.
    pub fn opt_usize(&self, name: &str) -> PyResult<Option<usize>> {
        self.get(name, "a non-negative integer")
    }

    /// A boolean, or `false`.
    pub fn flag(&self, name: &str) -> PyResult<bool> {
        Ok(self.get(name, "True or False")?.unwrap_or(false))
    }

    /// A string, or `default`.
    pub fn string(&self, name: &str, default: &str) -> PyResult<String> {
        Ok(self
            .get(name, "a string")?
            .unwrap_or_else(|| default.to_string()))
    }

    /// Three numbers (x, y, z), if given.
    pub fn triple(&self, name: &str) -> PyResult<Option<[f64; 3]>> {
        let t: Option<(f64, f64, f64)> = self.get(name, "three numbers (x, y, z)")?;
        Ok(t.map(|(x, y, z)| [x, y, z]))
    }

    /// One of `choices` (as spelled on the command line), if given.
    pub fn choice(&self, name: &str, default: &str, choices: &[&str]) -> PyResult<String> {
        let s = self.string(name, default)?;
        if choices.contains(&s.as_str()) {
            Ok(s)
        } else {
            Err(value_error(format!(
                "{}: option {name}='{s}' is not one of {}",
                self.function,
                choices.join(", ")
            )))
        }
    }
}
