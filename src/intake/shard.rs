//! Which scans a shard of a batch takes: a scan goes to shard `FNV-1a(customer id) mod N`
//! (see [`super::hash`]), so a scan's shard depends on its customer id and N only: adding
//! scans does not move the others. Shards are numbered from 1 on the command line
//! (`--shard K/N`, as nextest's `--partition hash:K/N`); Kubernetes' completion index and
//! Slurm's array task ids are turned into that.

use super::hash::fnv1a;
use std::fmt;

/// Slurm array jobs: this task's id, the array's task count, lowest id and step (`--array
/// 1-9:2` gives ids 1, 3, 5, 7, 9; the shard is `(ID - MIN) / STEP`).
pub const SLURM_ID: &str = "SLURM_ARRAY_TASK_ID";
/// See [`SLURM_ID`].
pub const SLURM_COUNT: &str = "SLURM_ARRAY_TASK_COUNT";
/// See [`SLURM_ID`].
pub const SLURM_MIN: &str = "SLURM_ARRAY_TASK_MIN";
/// See [`SLURM_ID`].
pub const SLURM_STEP: &str = "SLURM_ARRAY_TASK_STEP";
/// Kubernetes Indexed Jobs: this pod's index, 0 to completions - 1 (the count is not passed).
pub const K8S_INDEX: &str = "JOB_COMPLETION_INDEX";

/// One of `count` shards (`index` from 0).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    index: u64,
    count: u64,
}

impl Shard {
    /// Shard `index` (from 0) of `count`, if it is one.
    pub fn new(index: u64, count: u64) -> Result<Shard, String> {
        if count == 0 || index >= count {
            return Err(format!("shard {} of {count} does not exist", index + 1));
        }
        Ok(Shard { index, count })
    }

    /// `K/N` (K from 1 to N), as `--shard` takes it.
    pub fn parse(text: &str) -> Result<Shard, String> {
        let bad = || format!("--shard: '{text}' is not K/N (K from 1 to N, as in 2/8)");
        let (k, n) = text.split_once('/').ok_or_else(bad)?;
        let (k, n): (u64, u64) =
            (k.trim().parse().map_err(|_| bad())?, n.trim().parse().map_err(|_| bad())?);
        if k == 0 || k > n {
            return Err(bad());
        }
        Shard::new(k - 1, n)
    }

    /// The shard the environment names, read through `var`: a Slurm array task
    /// ([`SLURM_ID`]...) or a Kubernetes Indexed Job's pod ([`K8S_INDEX`], with `count` from
    /// `--shard-count`); `None` when neither is set. `count`, when given, must agree with
    /// Slurm's.
    pub fn from_env(
        var: impl Fn(&str) -> Option<String>,
        count: Option<u64>,
    ) -> Result<Option<Shard>, String> {
        let number = |name: &str| -> Result<Option<u64>, String> {
            var(name)
                .map(|v| {
                    v.trim()
                        .parse::<u64>()
                        .map_err(|_| format!("{name}: '{v}' is not a whole number"))
                })
                .transpose()
        };
        if let Some(id) = number(SLURM_ID)? {
            let total = number(SLURM_COUNT)?
                .ok_or_else(|| format!("{SLURM_ID} is set but {SLURM_COUNT} is not"))?;
            if let Some(n) = count.filter(|&n| n != total) {
                return Err(format!("--shard-count {n} disagrees with {SLURM_COUNT}={total}"));
            }
            let min = number(SLURM_MIN)?.unwrap_or(0);
            let step = number(SLURM_STEP)?.unwrap_or(1).max(1);
            let offset = id
                .checked_sub(min)
                .ok_or_else(|| format!("{SLURM_ID}={id} is below {SLURM_MIN}={min}"))?;
            return Shard::new(offset / step, total)
                .map(Some)
                .map_err(|e| format!("{SLURM_ID}={id}: {e}"));
        }
        if let Some(index) = number(K8S_INDEX)? {
            let n = count.ok_or_else(|| {
                format!("{K8S_INDEX} is set: pass the job's completions as --shard-count")
            })?;
            return Shard::new(index, n).map(Some).map_err(|e| format!("{K8S_INDEX}={index}: {e}"));
        }
        Ok(None)
    }

    /// Whether the scan of `customer` belongs to this shard.
    pub fn takes(&self, customer: &str) -> bool {
        fnv1a(customer.as_bytes()) % self.count == self.index
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index + 1, self.count)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn env<'a>(vars: &'a [(&'a str, &'a str)]) -> impl Fn(&str) -> Option<String> + 'a {
        move |name| vars.iter().find(|(k, _)| *k == name).map(|(_, v)| v.to_string())
    }

    #[test]
    fn every_customer_is_in_exactly_one_shard() {
        let shards: Vec<Shard> =
            (1..=3).map(|k| Shard::parse(&format!("{k}/3")).unwrap()).collect();
        for c in 0..100 {
            let id = format!("customer-{c}");
            assert_eq!(shards.iter().filter(|s| s.takes(&id)).count(), 1);
        }
        assert!(Shard::parse("0/3").is_err() && Shard::parse("4/3").is_err());
        assert!(Shard::parse("1/0").is_err() && Shard::parse("x").is_err());
    }

    #[test]
    fn slurm_and_kubernetes_name_the_same_shards() {
        let slurm = [(SLURM_ID, "5"), (SLURM_COUNT, "3"), (SLURM_MIN, "1"), (SLURM_STEP, "2")];
        assert_eq!(Shard::from_env(env(&slurm), None).unwrap(), Some(Shard::parse("3/3").unwrap()));
        let k8s = [(K8S_INDEX, "0")];
        assert_eq!(
            Shard::from_env(env(&k8s), Some(4)).unwrap(),
            Some(Shard::parse("1/4").unwrap())
        );
        assert!(Shard::from_env(env(&k8s), None).is_err());
        assert_eq!(Shard::from_env(env(&[]), None).unwrap(), None);
    }
}
