"""A small client for soupuv-server, standard library only.

    from soupuv_client import Client
    c = Client("http://127.0.0.1:8080", token=None)
    job = c.submit("Fox/Fox.gltf", params={"method": "field"}, metadata={"asset_id": "A-42"})
    job = c.wait(job["id"], progress=print)          # polls, honouring Retry-After
    c.download(job["id"], "fox-mapped.glb")          # also "diagnostics" -> .json

Or from a shell: python3 soupuv_client.py MODEL -o OUT.glb [--server URL]
[--params JSON] [--metadata JSON] [--token T].

What it sends: a .glb/.drc alone; a .gltf with every file it names (buffers,
images; relative paths inside its folder) as multipart "files" parts; a .zip as
is. Submissions answered 429 or 503 (queue full, server busy) are retried after
the Retry-After the server gives, up to `retries` times; so are connection
errors while polling. Any other refusal raises SoupuvError with the server's
problem+json (RFC 9457) detail.
"""
import json
import os
import sys
import time
import urllib.error
import urllib.parse
import urllib.request
import uuid

MEDIA = {".glb": "model/gltf-binary", ".gltf": "model/gltf+json", ".drc": "application/octet-stream",
         ".zip": "application/zip"}
FINISHED = ("succeeded", "failed", "canceled")


class SoupuvError(Exception):
    """A refusal or failure: HTTP status and the problem's detail."""

    def __init__(self, status, detail, problem=None):
        super().__init__(f"HTTP {status}: {detail}")
        self.status, self.detail, self.problem = status, detail, problem or {}


def gltf_files(path):
    """The files a .gltf names (buffers and images), as paths relative to its folder."""
    with open(path, "rb") as f:
        doc = json.load(f)
    names = []
    for key in ("buffers", "images"):
        for item in doc.get(key, []):
            uri = item.get("uri") if isinstance(item, dict) else None
            if isinstance(uri, str) and not uri.startswith("data:"):
                names.append(urllib.parse.unquote(uri))
    return names


def multipart(fields):
    """(body, content type) for [(name, filename or None, content type, bytes)]."""
    boundary = "soupuv-" + uuid.uuid4().hex
    out = []
    for name, filename, ctype, data in fields:
        disp = f'form-data; name="{name}"' + (f'; filename="{filename}"' if filename else "")
        out.append(f"--{boundary}\r\nContent-Disposition: {disp}\r\nContent-Type: {ctype}\r\n\r\n".encode())
        out.append(data)
        out.append(b"\r\n")
    out.append(f"--{boundary}--\r\n".encode())
    return b"".join(out), f"multipart/form-data; boundary={boundary}"


class Client:
    def __init__(self, base_url, token=None, retries=5, timeout=60):
        self.base = base_url.rstrip("/")
        self.token, self.retries, self.timeout = token, retries, timeout

    def _request(self, method, path, body=None, headers=None):
        """(status, headers, bytes); HTTP errors come back as values, not exceptions."""
        req = urllib.request.Request(self.base + path, data=body, method=method, headers=dict(headers or {}))
        if self.token:
            req.add_header("Authorization", f"Bearer {self.token}")
        try:
            with urllib.request.urlopen(req, timeout=self.timeout) as r:
                return r.status, r.headers, r.read()
        except urllib.error.HTTPError as e:
            return e.code, e.headers, e.read()

    @staticmethod
    def _problem(status, data):
        try:
            p = json.loads(data)
        except ValueError:
            p = {}
        return SoupuvError(status, p.get("detail") or p.get("title") or data[:200].decode(errors="replace"), p)

    def _retry_after(self, headers, attempt):
        try:
            return max(0.0, float(headers.get("Retry-After")))
        except (TypeError, ValueError):
            return min(30.0, 2.0 ** attempt)

    def submit(self, path, params=None, metadata=None, callback_url=None, idempotency_key=None):
        """Uploads a model (see the module doc); returns the job JSON."""
        params = dict(params or {})
        if metadata is not None:
            params["metadata"] = metadata
        if callback_url is not None:
            params["callback_url"] = callback_url
        ext = os.path.splitext(path)[1].lower()
        if ext not in MEDIA:
            raise SoupuvError(0, f"{path}: not a .glb, .gltf, .drc or .zip")
        with open(path, "rb") as f:
            fields = [("file", os.path.basename(path), MEDIA[ext], f.read())]
        if ext == ".gltf":
            folder = os.path.dirname(os.path.abspath(path))
            for name in gltf_files(path):
                with open(os.path.join(folder, name), "rb") as f:
                    fields.append(("files", name, "application/octet-stream", f.read()))
        fields.append(("params", None, "application/json", json.dumps(params).encode()))
        body, ctype = multipart(fields)
        # One key for every retry: a submission the server took but whose
        # answer was lost is not run twice.
        headers = {"Content-Type": ctype, "Idempotency-Key": idempotency_key or uuid.uuid4().hex}
        for attempt in range(self.retries + 1):
            status, h, data = self._request("POST", "/v1/jobs", body, headers)
            if status == 202:
                return json.loads(data)
            if status in (429, 503) and attempt < self.retries:
                time.sleep(self._retry_after(h, attempt))
                continue
            raise self._problem(status, data)

    def job(self, job_id):
        status, _, data = self._request("GET", f"/v1/jobs/{job_id}")
        if status != 200:
            raise self._problem(status, data)
        return json.loads(data)

    def wait(self, job_id, progress=None, timeout=3600):
        """Polls until the job ends, sleeping what Retry-After says; calls
        progress(job) on every poll; returns the finished job JSON."""
        end = time.monotonic() + timeout
        attempt = 0
        while time.monotonic() < end:
            try:
                status, h, data = self._request("GET", f"/v1/jobs/{job_id}")
            except OSError:  # connection refused or reset: the server restarting
                attempt += 1
                if attempt > self.retries:
                    raise
                time.sleep(min(30.0, 2.0 ** attempt))
                continue
            if status in (429, 503):
                time.sleep(self._retry_after(h, attempt))
                continue
            if status != 200:
                raise self._problem(status, data)
            job = json.loads(data)
            if progress:
                progress(job)
            if job["state"] in FINISHED:
                return job
            time.sleep(min(self._retry_after(h, 0), max(0.0, end - time.monotonic())))
        raise TimeoutError(f"job {job_id} did not finish within {timeout} s")

    def download(self, job_id, out_path, what="result"):
        """Writes the job's result GLB (or "diagnostics") to out_path."""
        status, _, data = self._request("GET", f"/v1/jobs/{job_id}/{what}")
        if status != 200:
            raise self._problem(status, data)
        with open(out_path, "wb") as f:
            f.write(data)
        return out_path


def progress_line(job):
    """One line per poll: state, stage and fraction."""
    stage = f" {job.get('stage', '')} {100 * job.get('fraction', 0):.0f}%" if job["state"] == "running" else ""
    print(f"{job['id']}: {job['state']}{stage}", file=sys.stderr)


def main(argv):
    import argparse
    ap = argparse.ArgumentParser(description="Map a model with soupuv-server.")
    ap.add_argument("model")
    ap.add_argument("-o", "--output", required=True)
    ap.add_argument("--server", default=os.environ.get("SOUPUV_URL", "http://127.0.0.1:8080"))
    ap.add_argument("--token", default=os.environ.get("SOUPUV_TOKEN"))
    ap.add_argument("--params", default="{}", help="JSON object of job parameters")
    ap.add_argument("--metadata", help="JSON object stored with the job")
    ap.add_argument("--diagnostics", help="also write the diagnostics JSON here")
    a = ap.parse_args(argv)
    c = Client(a.server, a.token)
    try:
        job = c.submit(a.model, json.loads(a.params), json.loads(a.metadata) if a.metadata else None)
        job = c.wait(job["id"], progress=progress_line)
        if job["state"] != "succeeded":
            err = job.get("error") or {}
            print(f"soupuv: job {job['state']}: {err.get('detail', '')}", file=sys.stderr)
            return 1
        c.download(job["id"], a.output)
        if a.diagnostics:
            c.download(job["id"], a.diagnostics, "diagnostics")
    except (SoupuvError, OSError, ValueError) as e:
        print(f"soupuv: {e}", file=sys.stderr)
        return 1
    print(a.output)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
