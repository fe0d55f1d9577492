#!/usr/bin/python3
"""Checks the scheduler files that run a sweep in shards (docs/schedulers/).

  scheduler_files_check.py WORKFLOW MANIFEST

Both files must parse as YAML (PyYAML, Debian's python3-yaml), and do what
docs/sweeps.md says:

  the GitHub Actions workflow: a matrix over the shard indices 1..N, made
  by a plan job whose step is run here for N = 4 (and must refuse 257, past
  a matrix's 256 jobs); a shard job whose command, run here with a stub in
  place of depthbench for each index, passes --shard K/N and writes and
  uploads shard-K.json; a merge job that needs the shard jobs, runs after a
  failed one, downloads every shard and passes them all to merge;

  the Kubernetes manifest: an Indexed Job whose completions equal the
  shard count its pods are given, whose command, run here for every
  completion index with the stub, passes index I as --shard I+1/N and
  writes each shard to its own file on a shared volume; a merge Job that
  mounts the same volume and passes every shard file to merge.

Then it plants mistakes in copies (a completion count one short, the
index passed as it is, a merge that does not wait for the shards, no
matrix) and each must be caught, so that the check itself can fail.
"""
import copy
import fnmatch
import os
import re
import subprocess
import sys
import tempfile

import yaml

SHARDS_TRIED = 4
# The stub that stands for depthbench: writes its arguments, one a line.
STUB = '#!/bin/sh\nfor a in "$@"; do printf "%s\\n" "$a"; done >> "$STUB_LOG"\n'


class Problem(Exception):
    pass


def expect(condition, message):
    if not condition:
        raise Problem(message)


def run_with_stub(command, env, cwd, stub_path):
    """Runs a command (a list) with the stub at stub_path; its arguments."""
    os.makedirs(os.path.dirname(stub_path), exist_ok=True)
    with open(stub_path, "w") as f:
        f.write(STUB)
    os.chmod(stub_path, 0o755)
    log = os.path.join(cwd, "stub.log")
    if os.path.exists(log):
        os.remove(log)
    full_env = {"PATH": os.environ.get("PATH", "/usr/bin:/bin"), "STUB_LOG": log}
    full_env.update(env)
    done = subprocess.run(command, env=full_env, cwd=cwd, capture_output=True, text=True, timeout=60)
    expect(done.returncode == 0, "%s failed (exit %d): %s" % (command, done.returncode, done.stderr.strip()))
    with open(log) as f:
        return f.read().splitlines()


def option(args, name):
    expect(name in args, "depthbench is run without %s: %s" % (name, " ".join(args)))
    return args[args.index(name) + 1]


# ------------------------------------------------------------ the workflow

def substitute(text, values):
    """Replaces the workflow's ${{ NAME }} expressions with values[NAME]."""
    def one(match):
        name = match.group(1)
        expect(name in values, "expression ${{ %s }} in %r is not one this check knows" % (name, text))
        return str(values[name])
    return re.sub(r"\$\{\{\s*([\w.]+)\s*\}\}", one, str(text))


def step_env(step, values):
    return {k: substitute(v, values) for k, v in (step.get("env") or {}).items()}


def steps_using(job, action):
    return [s for s in job.get("steps", []) if str(s.get("uses", "")).startswith(action + "@")]


def step_running(job, what, job_name):
    found = [s for s in job.get("steps", []) if what in str(s.get("run", ""))]
    expect(len(found) == 1, "job %s has %d steps running %r, not one" % (job_name, len(found), what))
    return found[0]


def check_workflow(doc, work):
    expect(isinstance(doc, dict), "the workflow is not a mapping")
    # YAML 1.1 reads the key `on` as true.
    triggers = doc.get("on", doc.get(True))
    expect(isinstance(triggers, dict) and "workflow_dispatch" in triggers, "the workflow has no workflow_dispatch")
    inputs = triggers["workflow_dispatch"].get("inputs") or {}
    for name in ("samples", "shards", "seed", "run_args"):
        expect(name in inputs, "the workflow has no input %r" % name)
    jobs = doc.get("jobs") or {}
    values = {"inputs." + k: v.get("default", "") for k, v in inputs.items()}
    values["inputs.shards"] = SHARDS_TRIED
    for name, job in jobs.items():
        expect("runs-on" in job and isinstance(job.get("steps"), list), "job %s has no runs-on or steps" % name)

    # The shard job: a matrix over the shard indices, from the plan job.
    shard_jobs = [n for n, j in jobs.items() if "shard" in ((j.get("strategy") or {}).get("matrix") or {})]
    expect(len(shard_jobs) == 1, "%d jobs have a matrix over shard, not one" % len(shard_jobs))
    shard_name = shard_jobs[0]
    shard_job = jobs[shard_name]
    expect(shard_job["strategy"].get("fail-fast") is False, "a failed shard cancels the others (fail-fast)")
    matrix = str(shard_job["strategy"]["matrix"]["shard"])
    m = re.fullmatch(r"\$\{\{\s*fromJSON\(needs\.(\w+)\.outputs\.(\w+)\)\s*\}\}", matrix)
    expect(m, "the shard matrix %r is not fromJSON(needs.PLAN.outputs.NAME)" % matrix)
    plan_name, output = m.groups()
    needs = lambda job: [job["needs"]] if isinstance(job.get("needs"), str) else list(job.get("needs") or [])
    expect(plan_name in needs(shard_job) and plan_name in jobs, "the shard job does not need job %s" % plan_name)
    plan = jobs[plan_name]
    m = re.fullmatch(r"\$\{\{\s*steps\.(\w+)\.outputs\.(\w+)\s*\}\}", str((plan.get("outputs") or {}).get(output)))
    expect(m and m.group(2) == output, "job %s has no output %s from a step" % (plan_name, output))
    plan_steps = [s for s in plan["steps"] if s.get("id") == m.group(1)]
    expect(len(plan_steps) == 1, "job %s has no step %s" % (plan_name, m.group(1)))
    plan_step = plan_steps[0]

    def plan_shards(count):
        out = os.path.join(work, "github_output")
        open(out, "w").close()
        env = step_env(plan_step, dict(values, **{"inputs.shards": count}))
        env["GITHUB_OUTPUT"] = out
        script = os.path.join(work, "plan.sh")
        with open(script, "w") as f:
            f.write(plan_step["run"])
        done = subprocess.run(["bash", "-eo", "pipefail", script], env=dict(os.environ, **env), capture_output=True,
                              text=True, timeout=60)
        with open(out) as f:
            lines = dict(l.split("=", 1) for l in f.read().splitlines() if "=" in l)
        return done.returncode, lines.get(output)

    code, shards = plan_shards(SHARDS_TRIED)
    expect(code == 0 and shards is not None, "the plan step failed for %d shards" % SHARDS_TRIED)
    expect(yaml.safe_load(shards) == list(range(1, SHARDS_TRIED + 1)),
           "the plan makes the matrix %s for %d shards, not 1..%d" % (shards, SHARDS_TRIED, SHARDS_TRIED))
    code, _ = plan_shards(257)
    expect(code != 0, "the plan step takes 257 shards, more jobs than a matrix holds")

    # Each shard: its command, with the stub as depthbench, and its upload.
    run_step = step_running(shard_job, "--shard", shard_name)
    uploads = steps_using(shard_job, "actions/upload-artifact")
    expect(len(uploads) == 1, "the shard job has %d uploads, not one" % len(uploads))
    artifact_names = []
    for k in range(1, SHARDS_TRIED + 1):
        here = dict(values, **{"matrix.shard": k})
        cwd = os.path.join(work, "shard-job-%d" % k)
        os.makedirs(cwd)
        with open(os.path.join(cwd, "step.sh"), "w") as f:
            f.write(run_step["run"])
        args = run_with_stub(["bash", "-eo", "pipefail", "step.sh"], step_env(run_step, here), cwd,
                             os.path.join(cwd, "depthbench-package", "run.sh"))
        expect(args[:1] == ["run"], "the shard step does not call depthbench run: %s" % args)
        expect(option(args, "--shard") == "%d/%d" % (k, SHARDS_TRIED),
               "matrix shard %d runs --shard %s" % (k, option(args, "--shard")))
        expect(option(args, "--json") == substitute(uploads[0]["with"]["path"], here),
               "shard %d writes %s but uploads %s" % (k, option(args, "--json"), uploads[0]["with"]["path"]))
        artifact_names.append(substitute(uploads[0]["with"]["name"], here))
    expect(len(set(artifact_names)) == SHARDS_TRIED, "shards upload under one name: %s" % artifact_names)

    # The merge job: after every shard, every shard downloaded and merged.
    merge_jobs = [n for n, j in jobs.items() if any(re.search(r"\bmerge\b", str(s.get("run", ""))) and
                                                    "--json" in str(s.get("run", "")) for s in j["steps"])]
    expect(len(merge_jobs) == 1, "%d jobs run depthbench merge, not one" % len(merge_jobs))
    merge_name = merge_jobs[0]
    merge_job = jobs[merge_name]
    expect(shard_name in needs(merge_job), "the merge job does not need the shard job %s" % shard_name)
    expect("!cancelled()" in str(merge_job.get("if", "")), "the merge job does not run after a failed shard")
    downloads = [s for s in steps_using(merge_job, "actions/download-artifact") if "pattern" in s.get("with", {})]
    expect(len(downloads) == 1, "the merge job does not download the shards by a pattern")
    pattern = downloads[0]["with"]["pattern"]
    expect(all(fnmatch.fnmatchcase(n, pattern) for n in artifact_names),
           "the pattern %s misses shards %s" % (pattern, artifact_names))
    expect(downloads[0]["with"].get("merge-multiple") is True, "the shards are downloaded into separate folders")
    cwd = os.path.join(work, "merge-job")
    shard_dir = os.path.join(cwd, downloads[0]["with"]["path"])
    os.makedirs(shard_dir)
    for k in range(1, SHARDS_TRIED + 1):
        open(os.path.join(shard_dir, "shard-%d.json" % k), "w").close()
    merge_step = step_running(merge_job, "merge", merge_name)
    with open(os.path.join(cwd, "step.sh"), "w") as f:
        f.write(merge_step["run"])
    env = step_env(merge_step, values)
    env["GITHUB_STEP_SUMMARY"] = os.path.join(cwd, "summary.md")
    args = run_with_stub(["bash", "-eo", "pipefail", "step.sh"], env, cwd,
                         os.path.join(cwd, "depthbench-package", "run.sh"))
    expect(args[:1] == ["merge"], "the merge step does not call depthbench merge: %s" % args)
    merged = sorted(os.path.basename(a) for a in args if a.endswith(".json") and a != option(args, "--json"))
    expect(merged == sorted("shard-%d.json" % k for k in range(1, SHARDS_TRIED + 1)),
           "merge is given %s" % merged)


# ------------------------------------------------------------ the manifest

def pod_container(job):
    containers = job["spec"]["template"]["spec"]["containers"]
    expect(len(containers) == 1, "job %s has %d containers, not one" % (job["metadata"]["name"], len(containers)))
    return containers[0]


def container_env(container):
    return {e["name"]: str(e["value"]) for e in container.get("env", []) if "value" in e}


def claim_mounts(job):
    """mountPath -> claimName of the job's volumes from PersistentVolumeClaims."""
    pod = job["spec"]["template"]["spec"]
    claims = {v["name"]: v["persistentVolumeClaim"]["claimName"] for v in pod.get("volumes", [])
              if "persistentVolumeClaim" in v}
    return {m["mountPath"]: claims[m["name"]] for m in pod_container(job).get("volumeMounts", [])
            if m["name"] in claims}


def on_claim(path, mounts):
    for mount, claim in mounts.items():
        if path.startswith(mount.rstrip("/") + "/"):
            return claim
    return None


def check_manifest(docs, work):
    docs = [d for d in docs if d]
    jobs = [d for d in docs if d.get("kind") == "Job"]
    indexed = [j for j in jobs if j["spec"].get("completionMode") == "Indexed"]
    expect(len(indexed) == 1, "the manifest has %d Indexed Jobs, not one" % len(indexed))
    sweep = indexed[0]
    completions = sweep["spec"].get("completions")
    expect(isinstance(completions, int) and completions > 0, "the Indexed Job has no completion count")
    container = pod_container(sweep)
    env = container_env(container)
    expect(env.get("SHARDS") == str(completions),
           "the Indexed Job has %s completions but its pods are told SHARDS=%s" % (completions, env.get("SHARDS")))
    claims = {d["metadata"]["name"] for d in docs if d.get("kind") == "PersistentVolumeClaim"}
    mounts = claim_mounts(sweep)
    expect(mounts and set(mounts.values()) <= claims, "the Indexed Job mounts no claim the manifest makes")
    command = container.get("command", []) + container.get("args", [])
    expect(command, "the Indexed Job's container has no command")

    cwd = os.path.join(work, "indexed-job")
    os.makedirs(cwd)
    stub = os.path.join(cwd, "depthbench")
    shard_files = set()
    for index in range(completions):
        # The program and the volume are the stub's and a folder here.
        args = run_with_stub(command, dict(env, JOB_COMPLETION_INDEX=str(index), DEPTHBENCH=stub,
                                           SHARD_DIR=os.path.join(cwd, "shards")), cwd, stub)
        expect(args[:1] == ["run"], "the Indexed Job does not call depthbench run: %s" % args)
        expect(option(args, "--shard") == "%d/%d" % (index + 1, completions),
               "completion index %d runs --shard %s" % (index, option(args, "--shard")))
        shard_files.add(option(args, "--json"))
    expect(len(shard_files) == completions, "the shards write %d files, not %d" % (len(shard_files), completions))
    # With the manifest's own SHARD_DIR, the shards' files land on the
    # shared volume.
    args = run_with_stub(command, dict(env, JOB_COMPLETION_INDEX="0", DEPTHBENCH=stub), cwd, stub)
    expect(on_claim(option(args, "--json"), mounts), "shard files go to %s, not to the shared volume" %
           option(args, "--json"))

    merges = [j for j in jobs if j is not sweep]
    expect(len(merges) == 1, "the manifest has %d Jobs besides the Indexed Job, not one merge" % len(merges))
    merge = merges[0]
    merge_container = pod_container(merge)
    merge_env = container_env(merge_container)
    expect(set(claim_mounts(merge).values()) & set(mounts.values()), "the merge Job does not mount the shards' volume")
    cwd = os.path.join(work, "merge-job")
    shard_dir = os.path.join(cwd, "shards")
    os.makedirs(shard_dir)
    for k in range(1, completions + 1):
        open(os.path.join(shard_dir, "shard-%d.json" % k), "w").close()
    stub = os.path.join(cwd, "depthbench")
    args = run_with_stub(merge_container.get("command", []) + merge_container.get("args", []),
                         dict(merge_env, DEPTHBENCH=stub, SHARD_DIR=shard_dir), cwd, stub)
    expect(args[:1] == ["merge"], "the merge Job does not call depthbench merge: %s" % args)
    given = sorted(a for a in args if a.startswith(shard_dir))
    expect(len(given) == completions, "merge is given %d of the %d shard files" % (len(given), completions))


# ------------------------------------------------------------ planted mistakes

def plant(mistake, check, *document):
    try:
        with tempfile.TemporaryDirectory() as work:
            check(*document, work)
    except Problem as p:
        print("caught, as it must be: %s: %s" % (mistake, p))
        return True
    print("FAIL: the check missed a planted mistake: %s" % mistake)
    return False


def planted_mistakes(workflow, manifest):
    caught = True

    def edited_manifest(edit):
        docs = copy.deepcopy(manifest)
        sweep = next(d for d in docs if d and d["spec"].get("completionMode") == "Indexed")
        edit(sweep)
        return docs

    def edited_workflow(edit):
        doc = copy.deepcopy(workflow)
        edit(doc["jobs"])
        return doc

    def unshifted(sweep):
        c = pod_container(sweep)
        c["args"] = [a.replace("JOB_COMPLETION_INDEX + 1", "JOB_COMPLETION_INDEX") for a in c["args"]]

    caught &= plant("completions one short of SHARDS", check_manifest,
                    edited_manifest(lambda s: s["spec"].__setitem__("completions", s["spec"]["completions"] - 1)))
    caught &= plant("the 0-based index passed as the shard", check_manifest, edited_manifest(unshifted))
    shard_job = next(n for n, j in workflow["jobs"].items() if "strategy" in j)
    merge_job = next(n for n, j in workflow["jobs"].items() if shard_job in (j.get("needs") or []))
    caught &= plant("a merge job that does not wait for the shards", check_workflow,
                    edited_workflow(lambda jobs: jobs[merge_job].__setitem__(
                        "needs", [n for n in jobs[merge_job]["needs"] if n != shard_job])))
    caught &= plant("no matrix", check_workflow, edited_workflow(lambda jobs: jobs[shard_job].pop("strategy")))
    return caught


def main():
    if len(sys.argv) != 3:
        print(__doc__)
        return 2
    workflow_path, manifest_path = sys.argv[1:]
    try:
        with open(workflow_path) as f:
            workflow = yaml.safe_load(f)
        with open(manifest_path) as f:
            manifest = list(yaml.safe_load_all(f))
    except yaml.YAMLError as e:
        print("FAIL: not YAML: %s" % e)
        return 1
    for name, check, document in [(workflow_path, check_workflow, workflow), (manifest_path, check_manifest, manifest)]:
        try:
            with tempfile.TemporaryDirectory() as work:
                check(document, work)
        except Problem as p:
            print("FAIL: %s: %s" % (name, p))
            return 1
        print("ok: %s" % name)
    return 0 if planted_mistakes(workflow, manifest) else 1


if __name__ == "__main__":
    sys.exit(main())
