#!/usr/bin/env bash
# Offline validation of deploy/: compose file, Prometheus config, Kubernetes manifests against
# the API schema, YAML lint, the Grafana dashboard's metrics against a live /metrics scrape, and
# the Dockerfile's runtime package list against what the binaries link.
# Usage: validate_deploy.sh <source dir> <build dir>
set -euo pipefail
src="$1"
build="$2"
deploy="$src/deploy"
work="$(mktemp -d)"
server_pid=""
cleanup() {
  [ -n "$server_pid" ] && kill "$server_pid" 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

echo "== docker-compose config"
docker-compose -f "$deploy/docker-compose.yml" config -q || fail "docker-compose.yml"
docker-compose -f "$deploy/docker-compose.yml" --profile load config --services | grep -qx loadtest \
  || fail "the load tester profile is missing"
# The server and the load tester read their bearer tokens from the compose secret.
docker-compose -f "$deploy/docker-compose.yml" --profile load config > "$work/compose.yaml"
/usr/bin/python3 - "$work/compose.yaml" <<'PY' || fail "compose token secret"
import sys, yaml
config = yaml.safe_load(open(sys.argv[1]))
assert "nidevo_tokens" in config["secrets"], "no secret nidevo_tokens"
for name in ("nidevo", "loadtest"):
    service = config["services"][name]
    sources = [s["source"] if isinstance(s, dict) else s for s in service.get("secrets", [])]
    assert "nidevo_tokens" in sources, f"{name} does not get the secret nidevo_tokens"
    assert service["environment"]["NIDEVO_TOKEN_FILE"] == "/run/secrets/nidevo_tokens", name
print("ok: server and load tester read /run/secrets/nidevo_tokens")
sessions = config["services"]["nidevo"]["environment"].get("NIDEVO_MAX_SESSIONS")
assert sessions is not None and 1 <= int(sessions) <= 16, f"compose NIDEVO_MAX_SESSIONS {sessions}"
open(sys.argv[1] + ".sessions", "w").write(str(int(sessions)))
print(f"ok: compose admits {sessions} sessions")
PY

echo "== promtool check config"
promtool check config "$deploy/prometheus/prometheus.yml" || fail "prometheus.yml"

echo "== yamllint"
yamllint -d "{extends: relaxed, rules: {line-length: {max: 110}}}" \
  "$deploy/docker-compose.yml" "$deploy/prometheus" "$deploy/grafana/provisioning" "$deploy/k8s" \
  || fail "yamllint"

echo "== kubectl kustomize + Kubernetes schema"
npm_dir="$build/npm"
[ -d "$npm_dir/node_modules/kubernetes-models" ] || fail "run scripts/setup.sh --tests first"
cp "$deploy/validate/validate_k8s.mjs" "$npm_dir/"
for dir in "$deploy/k8s/base" "$deploy/k8s/overlays/prometheus-operator"; do
  kubectl kustomize "$dir" > "$work/rendered.yaml" 2> "$work/kustomize.log" \
    || { cat "$work/kustomize.log"; fail "kustomize $dir"; }
  node "$npm_dir/validate_k8s.mjs" < "$work/rendered.yaml" || fail "schema of $dir"
done
# Facts the deployment guide relies on.
kubectl kustomize "$deploy/k8s/base" 2>/dev/null > "$work/base.yaml"
/usr/bin/python3 - "$work/base.yaml" "$work/compose.yaml.sessions" <<'PY' || fail "deployment invariants"
import re, sys
text = open(sys.argv[1]).read()
grace = int(re.search(r"terminationGracePeriodSeconds: (\d+)", text).group(1))
drain = float(re.search(r"NIDEVO_DRAIN_TIMEOUT_S: \"([\d.]+)\"", text).group(1))
pre_stop = int(re.search(r"command:\s*\n\s*- sleep\s*\n\s*- \"?(\d+)", text).group(1))
assert grace > drain + pre_stop, f"grace {grace} s must exceed drain {drain} s + preStop {pre_stop} s"
assert "service: nidevo.v1.OdometryService" in text, "readiness probe must check the service"
assert "clusterIP: None" in text, "headless Service missing"
# Bearer tokens: the file the server reads is the mounted Secret's key, read-only.
token_file = re.search(r"NIDEVO_TOKEN_FILE: \"?([^\"\n]+)", text).group(1)
mount = re.search(r"- mountPath: (\S+)\n\s+name: tokens\n\s+readOnly: true", text)
assert mount, "the tokens volume must be mounted read-only"
assert token_file == mount.group(1) + "/tokens", f"{token_file} is not the Secret's key"
assert re.search(r"name: tokens\n\s+secret:\n\s+secretName: nidevo-tokens", text), \
    "the tokens volume must come from the Secret nidevo-tokens"
print(f"ok: grace {grace} s > preStop {pre_stop} s + drain {drain} s")
# The session limit is the measured capacity, not the server's default (32), and the compose
# stack's is the same.
sessions = re.search(r"NIDEVO_MAX_SESSIONS: \"(\d+)\"", text)
assert sessions, "the ConfigMap must set NIDEVO_MAX_SESSIONS (the server's default is 32)"
compose = open(sys.argv[2]).read().strip()
assert sessions.group(1) == compose, f"ConfigMap {sessions.group(1)} sessions, compose {compose}"
print(f"ok: {sessions.group(1)} sessions per pod, as in compose")
PY

echo "== Grafana dashboard against a live /metrics"
"$build/bin/nidevo-server" --address 127.0.0.1:0 --metrics_address 127.0.0.1:0 \
  --port_file "$work/ports" 2> "$work/server.log" &
server_pid=$!
for _ in $(seq 1 300); do [ -s "$work/ports" ] && break; sleep 0.1; done
[ -s "$work/ports" ] || { cat "$work/server.log"; fail "server did not start"; }
metrics_port="$(awk '$1 == "metrics_port" {print $2}' "$work/ports")"
curl -sf "http://127.0.0.1:$metrics_port/metrics" > "$work/metrics.txt" || fail "scrape"
/usr/bin/python3 - "$deploy/grafana/dashboards/nidevo.json" "$work/metrics.txt" <<'PY' || fail "dashboard"
import json, re, sys
dashboard = json.load(open(sys.argv[1]))
exported = set()
for line in open(sys.argv[2]):
    if line.startswith("# TYPE "):
        name, kind = line.split()[2:4]
        exported.add(name)
        if kind == "histogram":
            exported.update({name + "_bucket", name + "_sum", name + "_count"})
used = set()
panels = dashboard["panels"]
for panel in panels:
    for target in panel.get("targets", []):
        used.update(re.findall(r"\bnidevo_[a-z_]+", target["expr"]))
missing = sorted(used - exported)
assert used, "the dashboard queries no nidevo metric"
assert not missing, f"dashboard uses metrics the server does not export: {missing}"
titles = " ".join(p["title"].lower() for p in panels)
for topic in ["latency", "stage", "outcome", "psr", "pose check", "active sessions", "dropped"]:
    assert topic in titles, f"no panel about {topic}"
print(f"ok: {len(panels)} panels, {len(used)} metrics, all exported")
PY

echo "== Dockerfile runtime packages cover the binaries' libraries"
/usr/bin/python3 - "$deploy/Dockerfile" "$build/bin/nidevo-server" "$build/bin/nidevo-client" <<'PY' || fail "Dockerfile"
import os, re, subprocess, sys
dockerfile = open(sys.argv[1]).read()
runtime = dockerfile[dockerfile.index("AS runtime"):]
install = re.search(r"apt-get install[^&]*", runtime, re.S).group(0)
listed = set(re.findall(r"\b(lib[a-z0-9+.\-]+)", install))
base = {"libc6", "libstdc++6", "libgcc-s1"}  # in debian:12-slim
needed = set()
for binary in sys.argv[2:]:
    dump = subprocess.run(["objdump", "-p", binary], capture_output=True, text=True, check=True)
    for lib in re.findall(r"NEEDED\s+(\S+)", dump.stdout):
        path = subprocess.run(["ldconfig", "-p"], capture_output=True, text=True).stdout
        m = re.search(r"\s" + re.escape(lib) + r" \(libc6,x86-64\) => (\S+)", path)
        assert m, f"{lib} not found by ldconfig"
        owner = None
        for path in {m.group(1), os.path.realpath(m.group(1))}:
            for candidate in (path, "/usr" + path if path.startswith("/lib/") else path):
                r = subprocess.run(["dpkg", "-S", candidate], capture_output=True, text=True)
                if r.returncode == 0:
                    owner = r
        assert owner, f"no Debian package owns {lib}"
        needed.add(owner.stdout.split(":")[0])
missing = sorted(needed - listed - base)
assert not missing, f"runtime stage lacks {missing}"
print(f"ok: {len(needed)} packages needed, all in the runtime stage or the base image")
PY
echo "deploy: all checks passed"
