//! Values keyed by parameter name: ordered for tables, a JSON object in reports.

use serde::ser::{Serialize, SerializeMap, Serializer};

/// Values by name in the model's order; serialised as a JSON object `{name: value}` (a name
/// given twice keeps its last value, as an object must).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Named<T>(pub Vec<(String, T)>);

impl<T> Named<T> {
    /// Pairs `names` with `values` (the shorter one decides the length).
    pub fn new<S: AsRef<str>>(names: &[S], values: impl IntoIterator<Item = T>) -> Self {
        Self(names.iter().map(|n| n.as_ref().to_string()).zip(values).collect())
    }

    /// Whether there are no entries.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// The entries in order.
    pub fn iter(&self) -> impl Iterator<Item = &(String, T)> {
        self.0.iter()
    }
}

impl<T: Serialize> Serialize for Named<T> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut map = serializer.serialize_map(Some(self.0.len()))?;
        for (k, v) in &self.0 {
            map.serialize_entry(k, v)?;
        }
        map.end()
    }
}
