//! Flat option maps (the JSON objects a user writes) read field by field, so that every error
//! names the option: a value of the wrong type, an option that does not apply, or an unknown one.

use serde::de::DeserializeOwned;
use serde_json::{Map, Value};

use crate::error::{Error, Result};

/// A map of options being read; what is left at the end is refused.
#[derive(Debug)]
pub struct Options {
    map: Map<String, Value>,
    what: String,
}

impl Options {
    /// Options of `what` (used in messages, e.g. "static step").
    #[must_use]
    pub fn new(map: Map<String, Value>, what: &str) -> Self {
        Self {
            map,
            what: what.to_owned(),
        }
    }

    /// Options from a JSON value, which must be an object (`null` is an empty one).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if `value` is not an object.
    pub fn from_value(value: Value, what: &str) -> Result<Self> {
        match value {
            Value::Object(map) => Ok(Self::new(map, what)),
            Value::Null => Ok(Self::new(Map::new(), what)),
            other => Err(Error::InvalidParameter(format!(
                "the options of a {what} must be a mapping (got {other})"
            ))),
        }
    }

    /// Removes and converts option `key`; `None` if absent or null.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `key` if its value has the wrong type. No option is a
    /// mapping: one is refused as such, since serde would read `{"any": null}` as the name
    /// `"any"` of an enumerated option (a DOF, `stop_at_monitor_zero`).
    pub fn take<T: DeserializeOwned>(&mut self, key: &str) -> Result<Option<T>> {
        match self.map.remove(key) {
            None | Some(Value::Null) => Ok(None),
            Some(v @ Value::Object(_)) => Err(Error::InvalidParameter(format!(
                "{} option {key} = {v}: a mapping, where a number, a string, a bool or a list is expected",
                self.what
            ))),
            Some(v) => {
                let shown = v.to_string();
                serde_json::from_value(v)
                    .map(Some)
                    .map_err(|e| Error::InvalidParameter(format!("{} option {key} = {shown}: {e}", self.what)))
            }
        }
    }

    /// As [`Options::take`], with a default.
    ///
    /// # Errors
    /// See [`Options::take`].
    pub fn take_or<T: DeserializeOwned>(&mut self, key: &str, default: T) -> Result<T> {
        Ok(self.take(key)?.unwrap_or(default))
    }

    /// Refuses what is left: options in `other_keys` "do not apply" (`context` says why), the rest
    /// are unknown.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming every option left.
    pub fn finish(self, other_keys: &[&str], context: &str) -> Result<()> {
        if self.map.is_empty() {
            return Ok(());
        }
        let (inapplicable, unknown): (Vec<&String>, Vec<&String>) = self
            .map
            .keys()
            .partition(|k| other_keys.contains(&k.as_str()));
        let list = |keys: &[&String]| {
            keys.iter()
                .map(|k| format!("'{k}'"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        let mut parts = Vec::new();
        if !inapplicable.is_empty() {
            parts.push(format!("[{}] do not apply to {context}", list(&inapplicable)));
        }
        if !unknown.is_empty() {
            parts.push(format!("[{}] are not options of a {}", list(&unknown), self.what));
        }
        Err(Error::InvalidParameter(format!(
            "{} options: {}",
            self.what,
            parts.join("; ")
        )))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn errors_name_the_option() {
        let Value::Object(map) = json!({"a": 1, "b": "x", "c": 2, "d": 3}) else {
            unreachable!()
        };
        let mut o = Options::new(map, "test");
        assert_eq!(o.take::<usize>("a").unwrap(), Some(1));
        let err = o.take::<usize>("b").unwrap_err().to_string();
        assert!(err.contains("option b"), "{err}");
        assert_eq!(o.take_or("missing", 7usize).unwrap(), 7);
        // An enumerated option's name given as a one-key mapping (serde's form of a unit
        // variant) is refused, not read as the name.
        let Value::Object(map) = json!({"dof": {"uz": null}}) else {
            unreachable!()
        };
        let err = Options::new(map, "test")
            .take::<crate::Dof>("dof")
            .unwrap_err()
            .to_string();
        assert!(err.contains("option dof = {\"uz\":null}: a mapping"), "{err}");
        let err = o.finish(&["c"], "this control").unwrap_err().to_string();
        assert!(
            err.contains("['c'] do not apply to this control") && err.contains("['d'] are not options"),
            "{err}"
        );
    }
}
