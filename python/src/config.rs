//! Keyword settings (`**config`) onto the Rust `<Type>Config` structs: each key is a field's
//! name; an unknown key or a value of the wrong type is an `InvalidInputError` naming it.

use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::error::invalid;

/// The keyword arguments of one call, taken one by one; [`Settings::finish`] refuses any left.
pub(crate) struct Settings<'py> {
    dict: Option<Bound<'py, PyDict>>,
    what: &'static str,
    /// Every key asked for, for the message about an unknown one.
    known: Vec<String>,
}

impl<'py> Settings<'py> {
    /// The settings of `what` (for messages: "align(method='loam')").
    pub(crate) fn new(dict: Option<&Bound<'py, PyDict>>, what: &'static str) -> PyResult<Self> {
        Ok(Self {
            dict: dict.map(PyDictMethods::copy).transpose()?,
            what,
            known: Vec::new(),
        })
    }

    /// Set `field` from the key of the same name, when given.
    pub(crate) fn take<T>(&mut self, key: &str, field: &mut T) -> PyResult<()>
    where
        T: for<'a> FromPyObject<'a, 'py>,
    {
        if let Some(v) = self.take_raw(key)? {
            *field = v.extract::<T>().map_err(|_| {
                invalid(format!(
                    "{}: setting {key}={} has the wrong type",
                    self.what,
                    v.repr().map_or_else(|_| "?".to_owned(), |r| r.to_string())
                ))
            })?;
        }
        Ok(())
    }

    /// The value of `key`, removed, when given.
    pub(crate) fn take_raw(&mut self, key: &str) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.known.push(key.to_owned());
        let Some(d) = &self.dict else {
            return Ok(None);
        };
        let v = d.get_item(key)?;
        if v.is_some() {
            d.del_item(key)?;
        }
        Ok(v)
    }

    /// Fails on any key not taken.
    pub(crate) fn finish(self) -> PyResult<()> {
        let Some(d) = self.dict else {
            return Ok(());
        };
        if let Some((k, _)) = d.iter().next() {
            return Err(invalid(format!(
                "{}: unknown setting {k}; known: {}",
                self.what,
                self.known.join(", ")
            )));
        }
        Ok(())
    }
}
