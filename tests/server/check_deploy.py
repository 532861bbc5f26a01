#!/usr/bin/env python3
"""Checks the deployment files as far as can be done without Docker or a cluster:
every YAML parses; ports, paths, probes and SOUPUV_* variables agree with what
soupuv-server --help documents; the Dockerfile runs as non-root with a
healthcheck on /healthz; nginx config passes `nginx -t` (when nginx exists).

usage: check_deploy.py SOURCE_DIR SOUPUV_SERVER_BIN
Prints 'N passed, M failed'; exits non-zero on any failure."""
import os
import re
import shutil
import subprocess
import sys
import tempfile

import yaml

src, server_bin = sys.argv[1], sys.argv[2]
results = []


def check(name, ok, detail=""):
    results.append(ok)
    print(("ok   " if ok else "FAIL ") + name + ("" if ok else ": " + detail))


help_text = subprocess.run([server_bin, "--help"], capture_output=True, text=True, check=True).stdout
env_vars = set(re.findall(r"\[(SOUPUV_[A-Z_]+)\]", help_text))
check("server --help lists env vars", len(env_vars) >= 10, help_text)
for flag in ["--host", "--port", "--data-dir", "--workers", "--queue-capacity", "--tokens-file"]:
    check(f"contract flag {flag}", flag in help_text)


def load_all(path):
    with open(path) as f:
        return [d for d in yaml.safe_load_all(f) if d is not None]


# ---- compose --------------------------------------------------------------------
compose = load_all(os.path.join(src, "deploy/docker-compose.yml"))[0]
svc = compose["services"]["soupuv"]
env = svc["environment"]
check("compose env vars are server options", set(env) <= env_vars, str(set(env) - env_vars))
port = env["SOUPUV_PORT"]
check("compose exposes the server port", str(port) in [str(p) for p in svc["expose"]])
check("compose healthcheck hits /healthz on the port",
      f"127.0.0.1:{port}/healthz" in " ".join(svc["healthcheck"]["test"]))
check("compose dockerfile exists", os.path.exists(os.path.join(src, "deploy", svc["build"]["context"], svc["build"]["dockerfile"])))
data_mount = [v for v in svc["volumes"] if v.endswith(":" + env["SOUPUV_DATA_DIR"])]
check("compose volume mounted at the data dir", len(data_mount) == 1, str(svc["volumes"]))
nginx_mount = compose["services"]["nginx"]["volumes"][0].split(":")[0]
check("compose nginx config exists", os.path.exists(os.path.join(src, "deploy", nginx_mount)))

# ---- kubernetes ---------------------------------------------------------------------
docs = []
for name in sorted(os.listdir(os.path.join(src, "deploy/k8s"))):
    if name.endswith(".yaml"):
        docs += load_all(os.path.join(src, "deploy/k8s", name))
kinds = {d["kind"]: d for d in docs}
for k in ["Deployment", "Service", "PersistentVolumeClaim", "ConfigMap"]:
    check(f"k8s has a {k}", k in kinds)
cm = kinds["ConfigMap"]["data"]
check("ConfigMap keys are server options", set(cm) <= env_vars, str(set(cm) - env_vars))
pod = kinds["Deployment"]["spec"]["template"]["spec"]
c = pod["containers"][0]
cport = c["ports"][0]["containerPort"]
check("container port = SOUPUV_PORT", str(cport) == cm["SOUPUV_PORT"], f"{cport} vs {cm['SOUPUV_PORT']}")
check("liveness probe /healthz", c["livenessProbe"]["httpGet"]["path"] == "/healthz")
check("readiness probe /readyz", c["readinessProbe"]["httpGet"]["path"] == "/readyz")
check("probes use the named port", c["livenessProbe"]["httpGet"]["port"] == c["ports"][0]["name"])
check("data volume at SOUPUV_DATA_DIR", c["volumeMounts"][0]["mountPath"] == cm["SOUPUV_DATA_DIR"])
check("volume is the PVC", pod["volumes"][0]["persistentVolumeClaim"]["claimName"] == kinds["PersistentVolumeClaim"]["metadata"]["name"])
check("ConfigMap referenced", c["envFrom"][0]["configMapRef"]["name"] == kinds["ConfigMap"]["metadata"]["name"])
check("runs as non-root", pod["securityContext"]["runAsNonRoot"] is True and pod["securityContext"]["runAsUser"] != 0)
svc_k = kinds["Service"]["spec"]
check("Service targets the pod port", svc_k["ports"][0]["targetPort"] == c["ports"][0]["name"])
check("Service selects the pods", svc_k["selector"] == kinds["Deployment"]["spec"]["selector"]["matchLabels"])
check("single replica with Recreate (SQLite store)", kinds["Deployment"]["spec"]["replicas"] == 1
      and kinds["Deployment"]["spec"]["strategy"]["type"] == "Recreate")

# ---- Dockerfile -------------------------------------------------------------------------
dockerfile = open(os.path.join(src, "docker/Dockerfile")).read()
check("multi-stage on Debian 12", len(re.findall(r"^FROM debian:12", dockerfile, re.M)) >= 2)
user = re.findall(r"^USER (\S+)", dockerfile, re.M)
check("non-root USER", bool(user) and not user[-1].startswith("0") and user[-1] != "root", str(user))
check("HEALTHCHECK on /healthz", re.search(r"HEALTHCHECK[\s\S]*?/healthz", dockerfile) is not None)
# (SOUPUV_DEPS is install-deps.sh's build-stage switch, not a server option.)
docker_env = set(re.findall(r"(?<!-D)(SOUPUV_[A-Z_]+)=", dockerfile)) - {"SOUPUV_DEPS"}
check("Dockerfile env vars are server options", docker_env <= env_vars, str(docker_env - env_vars))
m = re.search(r"SOUPUV_PORT=(\d+)", dockerfile)
check("EXPOSE = SOUPUV_PORT", m is not None and f"EXPOSE {m.group(1)}" in dockerfile)
check("installs deps through scripts/install-deps.sh", "scripts/install-deps.sh" in dockerfile)

# ---- nobody gets in by default ----------------------------------------------------------------
def loopback(host):
    return host in ("localhost", "::1") or str(host).startswith("127.")


def not_anonymous(name, env_map):
    host = str(env_map.get("SOUPUV_HOST", "127.0.0.1"))
    ok = loopback(host) or bool(env_map.get("SOUPUV_TOKENS_FILE"))
    check(f"{name}: a non-loopback host has a tokens file", ok, f"SOUPUV_HOST={host} without SOUPUV_TOKENS_FILE")
    check(f"{name}: not anonymous on purpose", str(env_map.get("SOUPUV_ALLOW_ANONYMOUS", "false")).lower()
          in ("0", "false", "no", "off"))


docker_env_map = dict(re.findall(r"(?<!-D)(SOUPUV_[A-Z_]+)=(\S+)", dockerfile))
not_anonymous("Dockerfile", docker_env_map)
not_anonymous("compose", env)
not_anonymous("k8s ConfigMap", cm)
# compose: the tokens file is a secret at SOUPUV_TOKENS_FILE; the only published port is on loopback.
secret_files = {k: v["file"] for k, v in compose.get("secrets", {}).items()}
check("compose tokens secret mounted where SOUPUV_TOKENS_FILE points",
      env.get("SOUPUV_TOKENS_FILE") in [f"/run/secrets/{n}" for n in svc.get("secrets", []) if n in secret_files],
      str(svc.get("secrets")))
check("compose tokens file is git-ignored",
      all(f.startswith("./secrets/") for f in secret_files.values())
      and "/deploy/secrets/" in open(os.path.join(src, ".gitignore")).read())
published = [p for s in compose["services"].values() for p in s.get("ports", [])]
check("compose publishes on 127.0.0.1 only", all(str(p).startswith("127.0.0.1:") for p in published), str(published))
# k8s: the tokens file comes from a Secret mounted at its directory.
tokens_dir = os.path.dirname(cm.get("SOUPUV_TOKENS_FILE", ""))
mounts = {m["name"]: m for m in c["volumeMounts"]}
vols = {v["name"]: v for v in pod["volumes"]}
secret_mounts = [m for n, m in mounts.items() if "secret" in vols.get(n, {}) and m["mountPath"] == tokens_dir]
check("k8s tokens Secret mounted at the tokens file's directory", len(secret_mounts) == 1, tokens_dir)
# Docker reads .dockerignore at the build context's root (compose: context ..).
ignore = os.path.join(src, "deploy", svc["build"]["context"], ".dockerignore")
check(".dockerignore at the build context root", os.path.exists(ignore))
if os.path.exists(ignore):
    patterns = open(ignore).read().split()
    check(".dockerignore keeps build trees and secrets out", {"build*", "deploy/secrets", ".git"} <= set(patterns),
          str(patterns))

# ---- a read-only root needs a writable /tmp; the image builds without test packages ----------
csec = c.get("securityContext", {})
if csec.get("readOnlyRootFilesystem"):
    tmp = [m for m in c["volumeMounts"] if m["mountPath"] == "/tmp"]
    check("k8s read-only root has a writable /tmp volume",
          len(tmp) == 1 and "emptyDir" in vols.get(tmp[0]["name"], {}), str(c["volumeMounts"]))
check("Dockerfile build stage installs build packages only", "SOUPUV_DEPS=build bash scripts/install-deps.sh" in dockerfile)
build_list = subprocess.run(["bash", os.path.join(src, "scripts/install-deps.sh"), "--print"],
                            env=dict(os.environ, SOUPUV_DEPS="build"), capture_output=True, text=True).stdout.split()
test_only = {"libgtest-dev", "libgmock-dev", "chromium", "nginx-light", "clang", "python3-yaml", "postgresql"}
check("SOUPUV_DEPS=build has no test-only package", bool(build_list) and not (set(build_list) & test_only),
      str(set(build_list) & test_only))
full_list = subprocess.run(["bash", os.path.join(src, "scripts/install-deps.sh"), "--print"],
                           env={k: v for k, v in os.environ.items() if k != "SOUPUV_DEPS"},
                           capture_output=True, text=True).stdout.split()
check("the full dependency list still has the test packages", test_only <= set(full_list))

# ---- nginx --------------------------------------------------------------------------------
conf = open(os.path.join(src, "deploy/nginx/soupuv.conf")).read()
check("nginx streams uploads", "proxy_request_buffering off" in conf)
m = re.search(r"client_max_body_size (\d+)m", conf)
check("nginx body cap = server default upload cap", m is not None and int(m.group(1)) * 2**20 == 268435456)
nginx = shutil.which("nginx") or ("/usr/sbin/nginx" if os.path.exists("/usr/sbin/nginx") else None)
if nginx:
    with tempfile.TemporaryDirectory() as d:
        site = conf.replace("server soupuv:8080;", "server 127.0.0.1:8080;").replace("listen 80;", "listen 127.0.0.1:18999;")
        main = (f"pid {d}/nginx.pid; error_log {d}/error.log; events {{}}\n"
                f"http {{ access_log off; client_body_temp_path {d}; proxy_temp_path {d}; "
                f"fastcgi_temp_path {d}; uwsgi_temp_path {d}; scgi_temp_path {d};\n{site}\n}}\n")
        open(os.path.join(d, "nginx.conf"), "w").write(main)
        r = subprocess.run([nginx, "-t", "-p", d, "-c", os.path.join(d, "nginx.conf")], capture_output=True, text=True)
        check("nginx -t accepts deploy/nginx/soupuv.conf", r.returncode == 0, r.stderr)

# ---- scale-out: compose with PostgreSQL, 2 replicas, nginx ------------------------------------
cl = load_all(os.path.join(src, "deploy/compose/docker-compose.yml"))[0]
cs = cl["services"]
check("cluster compose has postgres, soupuv, nginx", {"postgres", "soupuv", "nginx"} <= set(cs))
cenv = cs["soupuv"]["environment"]
check("cluster compose env vars are server options", set(cenv) <= env_vars, str(set(cenv) - env_vars))
check("cluster compose: two soupuv replicas", cs["soupuv"].get("deploy", {}).get("replicas", 1) >= 2)
db_url = str(cenv.get("SOUPUV_DATABASE_URL", ""))
check("cluster compose: database URL points at the postgres service",
      db_url.startswith("postgresql://") and "@postgres:5432/" in db_url, db_url)
check("cluster compose: postgres is Debian 12's major version (15)", str(cs["postgres"]["image"]).startswith("postgres:15"))
check("cluster compose: soupuv waits for a healthy postgres",
      cs["soupuv"].get("depends_on", {}).get("postgres", {}).get("condition") == "service_healthy")
check("cluster compose: no password in the file", "${SOUPUV_DB_PASSWORD" in open(
    os.path.join(src, "deploy/compose/docker-compose.yml")).read() and "POSTGRES_PASSWORD" in cs["postgres"]["environment"])
cpub = [p for sv in cs.values() for p in sv.get("ports", [])]
check("cluster compose publishes on 127.0.0.1 only (postgres not at all)",
      all(str(p).startswith("127.0.0.1:") for p in cpub) and not cs["postgres"].get("ports"), str(cpub))
check("cluster compose dockerfile exists", os.path.exists(os.path.join(
    src, "deploy/compose", cs["soupuv"]["build"]["context"], cs["soupuv"]["build"]["dockerfile"])))
cng = cs["nginx"]["volumes"][0].split(":")[0]
check("cluster compose nginx config exists", os.path.exists(os.path.join(src, "deploy/compose", cng)))
not_anonymous("cluster compose", cenv)
check("cluster compose tokens secret", cenv.get("SOUPUV_TOKENS_FILE") == "/run/secrets/soupuv-tokens"
      and cl["secrets"]["soupuv-tokens"]["file"].startswith("../secrets/"))

# ---- scale-out: Kubernetes (Deployment of N, PostgreSQL StatefulSet, KEDA on queue depth) -----
kdocs = []
for name in sorted(os.listdir(os.path.join(src, "deploy/k8s-postgres"))):
    if name.endswith(".yaml"):
        kdocs += load_all(os.path.join(src, "deploy/k8s-postgres", name))
kk = {}
for d in kdocs:
    kk.setdefault(d["kind"], []).append(d)
for k in ["Deployment", "StatefulSet", "Service", "ConfigMap", "ScaledObject", "TriggerAuthentication"]:
    check(f"k8s-postgres has a {k}", k in kk)
dep = kk["Deployment"][0]
kcm = kk["ConfigMap"][0]["data"]
check("k8s-postgres ConfigMap keys are server options", set(kcm) <= env_vars, str(set(kcm) - env_vars))
not_anonymous("k8s-postgres ConfigMap", kcm)
check("k8s-postgres: several replicas, rolling updates", dep["spec"]["replicas"] >= 2
      and dep["spec"]["strategy"]["type"] == "RollingUpdate")
kc = dep["spec"]["template"]["spec"]["containers"][0]
kenv = {e["name"]: e for e in kc.get("env", [])}
check("k8s-postgres: database URL from a Secret",
      "secretKeyRef" in kenv.get("SOUPUV_DATABASE_URL", {}).get("valueFrom", {}))
check("k8s-postgres env names are server options", set(kenv) <= env_vars)
check("k8s-postgres: probes /healthz and /readyz", kc["livenessProbe"]["httpGet"]["path"] == "/healthz"
      and kc["readinessProbe"]["httpGet"]["path"] == "/readyz")
check("k8s-postgres: container port = SOUPUV_PORT", str(kc["ports"][0]["containerPort"]) == kcm["SOUPUV_PORT"])
kvols = {v["name"]: v for v in dep["spec"]["template"]["spec"]["volumes"]}
kmounts = {m["mountPath"]: m["name"] for m in kc["volumeMounts"]}
check("k8s-postgres: data dir is per-pod scratch (no shared PVC)",
      "emptyDir" in kvols.get(kmounts.get(kcm["SOUPUV_DATA_DIR"]), {}))
check("k8s-postgres: tokens Secret at the tokens file's directory",
      "secret" in kvols.get(kmounts.get(os.path.dirname(kcm["SOUPUV_TOKENS_FILE"])), {}))
check("k8s-postgres: runs as non-root", dep["spec"]["template"]["spec"]["securityContext"]["runAsNonRoot"] is True)
sts = kk["StatefulSet"][0]
check("k8s-postgres: PostgreSQL 15 StatefulSet with its own volume",
      sts["spec"]["template"]["spec"]["containers"][0]["image"].startswith("postgres:15")
      and bool(sts["spec"].get("volumeClaimTemplates")))
pg_svc = [sv for sv in kk["Service"] if sv["spec"]["selector"] == sts["spec"]["selector"]["matchLabels"]]
check("k8s-postgres: a Service selects the PostgreSQL pod", len(pg_svc) == 1 and sts["spec"]["serviceName"] == pg_svc[0]["metadata"]["name"])
app_svc = [sv for sv in kk["Service"] if sv["spec"]["selector"] == dep["spec"]["selector"]["matchLabels"]]
check("k8s-postgres: a Service selects the soupuv pods", len(app_svc) == 1 and app_svc[0]["spec"]["ports"][0]["targetPort"] == kc["ports"][0]["name"])
so = kk["ScaledObject"][0]
trig = so["spec"]["triggers"][0]
check("KEDA scales the soupuv Deployment", so["spec"]["scaleTargetRef"]["name"] == dep["metadata"]["name"])
check("KEDA trigger counts the queue in soupuv_jobs", trig["type"] == "postgresql"
      and "soupuv_jobs" in trig["metadata"]["query"] and "queued" in trig["metadata"]["query"])
check("KEDA keeps at least the Deployment's replicas", so["spec"]["minReplicaCount"] >= 1)
check("KEDA authentication exists", trig["authenticationRef"]["name"] in
      [t["metadata"]["name"] for t in kk["TriggerAuthentication"]])
# The table the KEDA query reads is the one the migrations create.
schema = open(os.path.join(src, "server/src/pg_schema.cpp")).read()
check("KEDA query's table and states exist in the schema", "CREATE TABLE soupuv_jobs" in schema
      and "'queued','running'" in schema)
# nginx config of the cluster compose passes nginx -t too.
if nginx:
    cconf = open(os.path.join(src, "deploy/compose/nginx.conf")).read()
    with tempfile.TemporaryDirectory() as d:
        site = cconf.replace("server soupuv:8080;", "server 127.0.0.1:8080;").replace("listen 80;", "listen 127.0.0.1:18998;")
        main = (f"pid {d}/nginx.pid; error_log {d}/error.log; events {{}}\n"
                f"http {{ access_log off; client_body_temp_path {d}; proxy_temp_path {d}; "
                f"fastcgi_temp_path {d}; uwsgi_temp_path {d}; scgi_temp_path {d};\n{site}\n}}\n")
        open(os.path.join(d, "nginx.conf"), "w").write(main)
        r = subprocess.run([nginx, "-t", "-p", d, "-c", os.path.join(d, "nginx.conf")], capture_output=True, text=True)
        check("nginx -t accepts deploy/compose/nginx.conf", r.returncode == 0, r.stderr)
    check("cluster nginx streams uploads", "proxy_request_buffering off" in cconf)

passed = sum(results)
failed = len(results) - passed
print(f"{passed} passed, {failed} failed")
sys.exit(1 if failed else 0)
