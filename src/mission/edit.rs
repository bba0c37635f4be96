//! Saving into the user's own file: only what changed changes.
//!
//! The file the mission came from is parsed with `toml_edit`, which keeps
//! comments, key order and layout. The mission as the file meant it (with
//! every default filled in) and the mission now are both turned into TOML
//! trees and compared leaf by leaf; only the leaves that differ are written,
//! each keeping the spacing and comment around its value. A value equal to
//! its default that the file did not write stays unwritten, so saving an
//! unchanged mission gives back the same bytes. New items (an obstacle, a
//! section the file did not have) are added in TOML's usual style.
//!
//! Positions keep the form the file wrote them in: one written as
//! latitude/longitude is compared and written as latitude/longitude
//! (`geodetic::write_forms`), and an element added to an array of them (a
//! new obstacle) takes the form of the file's last one.

use toml_edit::{ArrayOfTables, DocumentMut, Item, Table, TableLike};

use super::model::Mission;

/// The text to save for `mission`, edited into `original` (the file as it
/// was read). `None` when `original` is not a mission file at all: the
/// caller then writes the whole mission afresh.
pub fn edit_in_place(mission: &Mission, original: &str) -> Option<String> {
    let mut doc: DocumentMut = original.parse().ok()?;
    let source = super::source::SourceMap::new(original);
    let (before, forms) = super::read::read_model(original, &source).ok()?;
    let mut old = tree(&before)?;
    let mut new = tree(mission)?;
    super::geodetic::write_forms(&mut old, &before, &forms);
    super::geodetic::write_forms(&mut new, mission, &forms);
    apply(doc.as_table_mut(), &old, &new);
    Some(doc.to_string())
}

/// The mission as a TOML tree with every field (defaults included).
fn tree(mission: &Mission) -> Option<toml::Table> {
    match toml::Value::try_from(mission).ok()? {
        toml::Value::Table(t) => Some(t),
        _ => None,
    }
}

/// Writes into `table` what differs between `old` and `new`.
fn apply(table: &mut dyn TableLike, old: &toml::Table, new: &toml::Table) {
    let empty = toml::Table::new();
    for (key, value) in new {
        let before = old.get(key);
        if before == Some(value) {
            continue;
        }
        match value {
            // A new latitude/longitude position: inline, as a position is written.
            toml::Value::Table(sub)
                if key != "origin"
                    && super::geodetic::is_position(sub)
                    && table.get(key).and_then(Item::as_table_like).is_none() =>
            {
                set_value(table, key, to_edit_value(value));
            }
            toml::Value::Table(sub) => {
                let old_sub = match before {
                    Some(toml::Value::Table(t)) => t,
                    _ => &empty,
                };
                if table.get(key).and_then(Item::as_table_like).is_none() {
                    let mut fresh = Table::new();
                    // In the model's order: before the next section the
                    // file has (an [origin] added again goes above
                    // [bounds], not after the obstacles).
                    fresh.set_position(position_before(table, new, key));
                    table.insert(key, Item::Table(fresh));
                }
                if let Some(child) = table.get_mut(key).and_then(Item::as_table_like_mut) {
                    apply(child, old_sub, sub);
                }
            }
            toml::Value::Array(items) if is_array_of_tables(items) => {
                let old_items: &[toml::Value] = match before {
                    Some(toml::Value::Array(a)) => a,
                    _ => &[],
                };
                apply_array_of_tables(table, key, old_items, items);
            }
            _ => set_value(table, key, to_edit_value(value)),
        }
    }
    let gone: Vec<String> = old
        .keys()
        .filter(|k| !new.contains_key(*k))
        .cloned()
        .collect();
    for key in gone {
        table.remove(&key);
    }
}

/// The document position for a new section `key` of `table` that puts it
/// just before the first section after `key` in `model`'s order that the
/// file already has; `None` (the end) when the file has none after it.
fn position_before(table: &dyn TableLike, model: &toml::Table, key: &str) -> Option<isize> {
    let first = |item: &Item| match item {
        Item::Table(t) => t.position(),
        Item::ArrayOfTables(a) => a.iter().next().and_then(Table::position),
        _ => None,
    };
    model
        .keys()
        .skip_while(|k| k.as_str() != key)
        .skip(1)
        .find_map(|k| table.get(k).and_then(first))
        .map(|p| p - 1)
}

fn is_array_of_tables(items: &[toml::Value]) -> bool {
    !items.is_empty() && items.iter().all(toml::Value::is_table)
}

/// `[[key]]` sections: element by element, then added or removed at the end.
/// A file that wrote them inline (`key = [{...}]`) gets the whole array.
fn apply_array_of_tables(
    table: &mut dyn TableLike,
    key: &str,
    old: &[toml::Value],
    new: &[toml::Value],
) {
    if !matches!(table.get(key), Some(Item::ArrayOfTables(_))) {
        if table.get(key).is_some() {
            // Written inline: replace the value, keep its decoration.
            let array = toml::Value::Array(new.to_vec());
            set_value(table, key, to_edit_value(&array));
            return;
        }
        table.insert(key, Item::ArrayOfTables(ArrayOfTables::new()));
    }
    let Some(Item::ArrayOfTables(array)) = table.get_mut(key) else {
        return;
    };
    let empty = toml::Table::new();
    for (i, value) in new.iter().enumerate() {
        let toml::Value::Table(new_t) = value else {
            continue;
        };
        let old_t = match old.get(i) {
            Some(toml::Value::Table(t)) => t,
            _ => &empty,
        };
        if i >= array.len() {
            array.push(Table::new());
        }
        if let Some(child) = array.get_mut(i) {
            apply(child, old_t, new_t);
        }
    }
    while array.len() > new.len() {
        array.remove(array.len() - 1);
    }
}

/// Replaces (or adds) `key`'s value, keeping the spacing and comment the
/// old value had.
fn set_value(table: &mut dyn TableLike, key: &str, mut value: toml_edit::Value) {
    match table.get_mut(key) {
        Some(Item::Value(old)) => {
            *value.decor_mut() = old.decor().clone();
            *old = value;
        }
        Some(item) => *item = Item::Value(value),
        None => {
            table.insert(key, Item::Value(value));
        }
    }
}

/// A `toml` value as a `toml_edit` one; tables become inline tables.
fn to_edit_value(value: &toml::Value) -> toml_edit::Value {
    match value {
        toml::Value::String(s) => s.as_str().into(),
        toml::Value::Integer(i) => (*i).into(),
        toml::Value::Float(f) => (*f).into(),
        toml::Value::Boolean(b) => (*b).into(),
        toml::Value::Datetime(d) => (*d).into(),
        toml::Value::Array(items) => {
            let array: toml_edit::Array = items.iter().map(to_edit_value).collect();
            toml_edit::Value::Array(array)
        }
        toml::Value::Table(t) => {
            let mut inline = toml_edit::InlineTable::new();
            for (k, v) in t {
                inline.insert(k, to_edit_value(v));
            }
            toml_edit::Value::InlineTable(inline)
        }
    }
}
