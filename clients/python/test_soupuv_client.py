"""Tests of soupuv_client: against a real soupuv-server process (with the real
CLI as worker) for submit / wait / download of a .gltf with its files, and
against small fake servers for what a real one rarely does on cue (429 with
Retry-After on submit, Retry-After while polling).

    SOUPUV_SERVER_BIN=... SOUPUV_CLI_BIN=... SOUPUV_SHARED_DATA=... python3 -m unittest -v test_soupuv_client
"""
import http.server
import json
import os
import re
import subprocess
import tempfile
import threading
import time
import unittest

import soupuv_client
from soupuv_client import Client, SoupuvError

SERVER = os.environ.get("SOUPUV_SERVER_BIN", "")
CLI = os.environ.get("SOUPUV_CLI_BIN", "")
DATA = os.environ.get("SOUPUV_SHARED_DATA", "")
PLANE = os.path.join(DATA, "gltf", "TwoSidedPlane", "TwoSidedPlane.gltf")


class FakeServer:
    """Answers from a list of (status, headers, body) per method, then repeats the last."""

    def __init__(self, answers):
        self.answers, self.requests = answers, []
        outer = self

        class Handler(http.server.BaseHTTPRequestHandler):
            def log_message(self, *args):
                pass

            def _answer(self):
                n = int(self.headers.get("Content-Length") or 0)
                outer.requests.append((self.command, self.path, dict(self.headers), self.rfile.read(n)))
                queue = outer.answers[self.command]
                status, headers, body = queue.pop(0) if len(queue) > 1 else queue[0]
                data = json.dumps(body).encode()
                self.send_response(status)
                for k, v in headers.items():
                    self.send_header(k, v)
                self.send_header("Content-Type", "application/json")
                self.send_header("Content-Length", str(len(data)))
                self.end_headers()
                self.wfile.write(data)

            do_GET = do_POST = _answer

        self.httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.url = f"http://127.0.0.1:{self.httpd.server_address[1]}"
        threading.Thread(target=self.httpd.serve_forever, daemon=True).start()

    def close(self):
        self.httpd.shutdown()
        self.httpd.server_close()


class Retries(unittest.TestCase):
    def test_submit_retries_429_after_retry_after_with_one_key(self):
        busy = (429, {"Retry-After": "0.3"}, {"title": "busy", "detail": "queue full"})
        fake = FakeServer({"POST": [busy, busy, (202, {}, {"id": "j1", "state": "queued"})]})
        try:
            with tempfile.NamedTemporaryFile(suffix=".glb") as f:
                f.write(b"glTF")
                f.flush()
                start = time.monotonic()
                job = Client(fake.url, retries=3).submit(f.name, metadata={"asset": 1})
                elapsed = time.monotonic() - start
        finally:
            fake.close()
        self.assertEqual(job["id"], "j1")
        posts = [r for r in fake.requests if r[0] == "POST"]
        self.assertEqual(len(posts), 3)
        self.assertGreaterEqual(elapsed, 0.55)  # two waits of Retry-After 0.3 s
        keys = {r[2].get("Idempotency-Key") for r in posts}
        self.assertEqual(len(keys), 1, "every retry carries the same Idempotency-Key")
        self.assertIn(b'"metadata": {"asset": 1}', posts[0][3])

    def test_gives_up_and_raises_the_problem(self):
        fake = FakeServer({"POST": [(503, {"Retry-After": "0"}, {"title": "busy", "detail": "uploads busy"})]})
        try:
            with tempfile.NamedTemporaryFile(suffix=".glb") as f:
                with self.assertRaises(SoupuvError) as e:
                    Client(fake.url, retries=2).submit(f.name)
        finally:
            fake.close()
        self.assertEqual(e.exception.status, 503)
        self.assertEqual(e.exception.detail, "uploads busy")
        self.assertEqual(len(fake.requests), 3)

    def test_wait_sleeps_what_retry_after_says(self):
        running = (200, {"Retry-After": "0.4"}, {"id": "j1", "state": "running", "stage": "charge", "fraction": 0.5})
        fake = FakeServer({"GET": [running, (200, {}, {"id": "j1", "state": "succeeded"})]})
        seen = []
        try:
            start = time.monotonic()
            job = Client(fake.url).wait("j1", progress=lambda j: seen.append(j["state"]))
            elapsed = time.monotonic() - start
        finally:
            fake.close()
        self.assertEqual(job["state"], "succeeded")
        self.assertEqual(seen, ["running", "succeeded"])
        self.assertGreaterEqual(elapsed, 0.35)


@unittest.skipUnless(SERVER and CLI and os.path.exists(PLANE),
                     "needs SOUPUV_SERVER_BIN, SOUPUV_CLI_BIN and the shared sample data")
class RealServer(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.proc = subprocess.Popen([SERVER, "--host", "127.0.0.1", "--port", "0", "--data-dir", cls.tmp.name,
                                     "--worker-bin", CLI, "--workers", "1"],
                                    stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        for line in cls.proc.stderr:
            m = re.search(r'"msg":"listening","port":(\d+)', line)
            if m:
                cls.url = f"http://127.0.0.1:{m.group(1)}"
                break
        else:
            raise RuntimeError("soupuv-server did not start")
        threading.Thread(target=lambda: [None for _ in cls.proc.stderr], daemon=True).start()

    @classmethod
    def tearDownClass(cls):
        cls.proc.terminate()
        cls.proc.wait(30)
        cls.tmp.cleanup()

    def test_gltf_with_its_files_submit_wait_download(self):
        c = Client(self.url)
        self.assertEqual(sorted(soupuv_client.gltf_files(PLANE))[0], "TwoSidedPlane.bin")
        job = c.submit(PLANE, params={"method": "box", "texture_size": 128}, metadata={"asset_id": "A-42"})
        self.assertEqual(job["metadata"], {"asset_id": "A-42"})
        states = []
        job = c.wait(job["id"], progress=lambda j: states.append(j["state"]), timeout=120)
        self.assertEqual(job["state"], "succeeded", job)
        self.assertEqual(job["metadata"], {"asset_id": "A-42"})
        self.assertEqual(states[-1], "succeeded")
        with tempfile.TemporaryDirectory() as out:
            glb = c.download(job["id"], os.path.join(out, "plane.glb"))
            with open(glb, "rb") as f:
                self.assertEqual(f.read(4), b"glTF")
            diag = c.download(job["id"], os.path.join(out, "plane.json"), "diagnostics")
            with open(diag) as f:
                self.assertEqual(json.load(f)["output"]["texture"]["source"], "rebake")

    def test_refusal_is_a_problem(self):
        with self.assertRaises(SoupuvError) as e:
            Client(self.url).submit(PLANE, params={"method": "magic"})
        self.assertEqual(e.exception.status, 400)
        self.assertIn("method", e.exception.detail)

    def test_command_line(self):
        with tempfile.TemporaryDirectory() as out:
            r = subprocess.run(["python3", soupuv_client.__file__, PLANE, "-o", os.path.join(out, "p.glb"),
                                "--server", self.url, "--params", '{"method":"box"}'],
                               capture_output=True, text=True, timeout=120)
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertTrue(os.path.getsize(os.path.join(out, "p.glb")) > 100)
            self.assertIn("succeeded", r.stderr)


if __name__ == "__main__":
    unittest.main()
