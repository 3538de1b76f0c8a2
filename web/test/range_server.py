#!/usr/bin/env python3
"""A static file server with HTTP range requests (single ranges), for the web player's tests.

  range_server.py DIR [--no-range] [--mount /PREFIX=DIR2]

Listens on 127.0.0.1 at a free port and prints `port N` on its first line; with --no-range it
answers every request with the whole file (200), as a server without range support does. With
--mount, paths under /PREFIX/ are served from DIR2 (e.g. clips written outside DIR). Each
request is logged to stderr as `GET PATH RANGE STATUS BYTES`.
"""

import http.server
import os
import re
import sys


class Handler(http.server.SimpleHTTPRequestHandler):
    ranges = True
    mounts = {}

    def translate_path(self, path):
        for prefix, root in self.mounts.items():
            if path.startswith(prefix + "/"):
                rest = path[len(prefix) + 1:].split("?", 1)[0].split("#", 1)[0]
                parts = [p for p in rest.split("/") if p not in ("", ".", "..")]
                return os.path.join(root, *parts)
        return super().translate_path(path)

    def log_message(self, fmt, *args):
        pass

    def do_GET(self):
        path = self.translate_path(self.path)
        if not os.path.isfile(path):
            self.send_error(404)
            return
        with open(path, "rb") as f:
            data = f.read()
        header = self.headers.get("Range")
        m = re.fullmatch(r"bytes=(\d+)-(\d*)", header or "")
        if self.ranges and m:
            start = int(m.group(1))
            end = min(int(m.group(2)) + 1 if m.group(2) else len(data), len(data))
            if start >= len(data) or start >= end:
                self.send_response(416)
                self.send_header("Content-Range", f"bytes */{len(data)}")
                self.end_headers()
                return
            body = data[start:end]
            self.send_response(206)
            self.send_header("Content-Range", f"bytes {start}-{end - 1}/{len(data)}")
        else:
            body = data
            self.send_response(200)
        self.send_header("Content-Type", self.guess_type(path))
        self.send_header("Content-Length", str(len(body)))
        if self.ranges:
            self.send_header("Accept-Ranges", "bytes")
        self.end_headers()
        self.wfile.write(body)
        print(f"GET {self.path} {header} {len(body)}", file=sys.stderr, flush=True)


def main():
    Handler.ranges = "--no-range" not in sys.argv
    for i, arg in enumerate(sys.argv):
        if arg == "--mount" and i + 1 < len(sys.argv):
            prefix, root = sys.argv[i + 1].split("=", 1)
            Handler.mounts[prefix.rstrip("/")] = os.path.abspath(root)
    os.chdir(sys.argv[1])
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Handler)
    print(f"port {server.server_address[1]}", flush=True)
    server.serve_forever()


if __name__ == "__main__":
    main()
