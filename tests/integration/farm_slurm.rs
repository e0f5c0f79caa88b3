//! The render farm on a real Slurm cluster (scaffold: the cluster runs an array job).

use std::time::Duration;

use crate::slurm_cluster::SlurmCluster;

#[test]
fn a_job_array_runs_on_the_test_cluster() {
    let cluster = match SlurmCluster::start() {
        Ok(cluster) => cluster,
        Err(why) => {
            eprintln!("no Slurm here: {why}");
            return;
        }
    };
    let out = cluster.path().join("out");
    std::fs::create_dir_all(&out).unwrap();
    let output = cluster.run(
        "sbatch",
        &[
            "--parsable",
            "--array=0-2",
            "--mem=10M",
            &format!("--output={}/%a.txt", out.display()),
            "--wrap",
            "echo $SLURM_ARRAY_TASK_ID/$SLURM_ARRAY_TASK_COUNT",
        ],
    );
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let job = String::from_utf8_lossy(&output.stdout).trim().to_string();
    cluster.wait_for(&job, Duration::from_secs(60));
    assert_eq!(cluster.job_state(&format!("{job}_1")), "COMPLETED");
    for i in 0..3 {
        let text = std::fs::read_to_string(out.join(format!("{i}.txt"))).unwrap();
        assert_eq!(text.trim(), format!("{i}/3"));
    }
}
