//! Agents as the fleet's JSON numbers them: from 1, as the summary, the
//! log and the designer do (`agent 3` is `"agent": 3` everywhere). The
//! code keeps 0-based indices; these serialise them.

use serde::Serializer;
use serde::ser::SerializeSeq;

/// A 0-based index as its number from 1.
pub fn one<S: Serializer>(index: &usize, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_u64(*index as u64 + 1)
}

/// An optional 0-based index as its number from 1.
pub fn maybe<S: Serializer>(index: &Option<usize>, s: S) -> Result<S::Ok, S::Error> {
    match index {
        Some(i) => s.serialize_some(&(*i as u64 + 1)),
        None => s.serialize_none(),
    }
}

/// 0-based indices as numbers from 1.
pub fn ones<S: Serializer>(indices: &[usize], s: S) -> Result<S::Ok, S::Error> {
    let mut seq = s.serialize_seq(Some(indices.len()))?;
    for i in indices {
        seq.serialize_element(&(*i as u64 + 1))?;
    }
    seq.end()
}

/// Per sample, pairs of 0-based agents as pairs numbered from 1.
pub fn links<S: Serializer>(samples: &[Vec<(usize, usize)>], s: S) -> Result<S::Ok, S::Error> {
    let numbered: Vec<Vec<(usize, usize)>> = samples
        .iter()
        .map(|pairs| pairs.iter().map(|&(a, b)| (a + 1, b + 1)).collect())
        .collect();
    serde::Serialize::serialize(&numbered, s)
}

#[cfg(test)]
mod tests {
    #[derive(serde::Serialize)]
    struct Lost {
        #[serde(serialize_with = "super::one")]
        agent: usize,
        #[serde(serialize_with = "super::maybe")]
        other: Option<usize>,
        #[serde(serialize_with = "super::ones")]
        list: Vec<usize>,
    }

    #[test]
    fn agent_2_zero_based_is_agent_3_in_the_json() {
        let text = serde_json::to_string(&Lost {
            agent: 2,
            other: None,
            list: vec![0, 4],
        })
        .unwrap_or_default();
        assert_eq!(text, r#"{"agent":3,"other":null,"list":[1,5]}"#);
    }
}
