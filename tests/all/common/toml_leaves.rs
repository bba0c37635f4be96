//! The numeric leaves of a TOML tree, found and changed one at a time: the
//! extreme-value sweeps walk every number a shipped mission writes.

/// Where a numeric leaf is: keys and array indices from the root.
#[derive(Debug, Clone)]
pub enum Step {
    Key(String),
    Index(usize),
}

/// Every numeric leaf under `value`, with whether it is an integer.
pub fn leaves(value: &toml::Value, at: &mut Vec<Step>, out: &mut Vec<(Vec<Step>, bool)>) {
    match value {
        toml::Value::Integer(_) => out.push((at.clone(), true)),
        toml::Value::Float(_) => out.push((at.clone(), false)),
        toml::Value::Array(items) => {
            for (i, item) in items.iter().enumerate() {
                at.push(Step::Index(i));
                leaves(item, at, out);
                at.pop();
            }
        }
        toml::Value::Table(table) => {
            for (key, item) in table {
                at.push(Step::Key(key.clone()));
                leaves(item, at, out);
                at.pop();
            }
        }
        _ => {}
    }
}

/// The leaf at `at`, to change.
pub fn leaf_mut<'a>(value: &'a mut toml::Value, at: &[Step]) -> &'a mut toml::Value {
    at.iter().fold(value, |v, step| match step {
        Step::Key(k) => &mut v[k.as_str()],
        Step::Index(i) => &mut v[*i],
    })
}
