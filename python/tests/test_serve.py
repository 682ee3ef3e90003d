"""`ecvpose serve` as a process: standard input and a Unix socket, SIGTERM during a frame, stale socket files."""

import json
import os
import signal
import socket
import subprocess
import time

import pytest

from conftest import DEMO_FRAME


def start(library_path, *flags):
    # The service reads frames only below its roots: the demo frame's folder.
    process = subprocess.Popen([os.environ["ECVPOSE_CLI"], "serve", "--db", str(library_path), "--threads", "2",
                                "--root", os.path.dirname(DEMO_FRAME), *flags], stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               text=True)
    for line in process.stderr:  # the library and meshes are loaded before "ready"
        if "ready" in line:
            return process
    raise AssertionError(f"serve ended before it was ready: {process.wait()}")


def request(**fields):
    return json.dumps(dict(frame=DEMO_FRAME, **fields)) + "\n"


def test_sigterm_during_a_frame_answers_it_then_exits_0(demo_library_path):
    process = start(demo_library_path)
    process.stdin.write(request(id="first"))
    process.stdin.flush()
    time.sleep(0.3)  # read by then; the frame takes about half a second (answered first if it ends sooner)
    process.send_signal(signal.SIGTERM)
    out, _ = process.communicate(timeout=60)
    assert process.returncode == 0
    [line] = out.splitlines()
    answer = json.loads(line)
    assert answer["id"] == "first" and len(answer["detections"]) == 3


def test_the_end_of_standard_input_ends_the_service(demo_library_path):
    process = start(demo_library_path)
    out, _ = process.communicate(request(id=1) + "\n" + request(id=2), timeout=60)
    assert process.returncode == 0
    assert [json.loads(line)["id"] for line in out.splitlines()] == [1, 2]  # the empty line is skipped


class Client:
    def __init__(self, path):
        self.connection = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        self.connection.connect(path)
        self.lines = self.connection.makefile("r")

    def ask(self, line):
        self.connection.sendall(line.encode())
        return json.loads(self.lines.readline())

    def close(self):
        self.lines.close()
        self.connection.close()


def tracked(answer):
    return [detection["tracked"] for detection in answer["detections"]]


def followed(answer):
    """Per detection: tracked, or confirmed by the search its new track was due for (that pose scored higher)."""
    return [detection["tracked"] or detection["confirmed"] for detection in answer["detections"]]


def test_a_socket_serves_clients_one_after_another_each_with_its_own_tracks(demo_library_path, tmp_path):
    path = str(tmp_path / "ecvpose.sock")
    stale = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    stale.bind(path)  # a socket file left behind by a service that was killed
    stale.close()
    process = start(demo_library_path, "--socket", path, "--track")
    try:
        first = Client(path)
        assert tracked(first.ask(request(id=1))) == [False] * 3
        assert followed(first.ask(request(id=2))) == [True] * 3
        assert "error" in first.ask("{\"id\": 3, \"frame\": 7}\n")
        assert first.ask(request(id=4, track=False))["id"] == 4
        first.close()
        second = Client(path)
        assert tracked(second.ask(request(id=5))) == [False] * 3  # a new client starts without tracks
        second.close()
    finally:
        process.send_signal(signal.SIGTERM)
        process.communicate(timeout=60)
    assert process.returncode == 0
    assert not os.path.exists(path)


def test_a_socket_path_holding_another_file_is_refused(demo_library_path, tmp_path):
    path = tmp_path / "notes.txt"
    path.write_text("keep me")
    run = subprocess.run([os.environ["ECVPOSE_CLI"], "serve", "--db", str(demo_library_path), "--socket", str(path)],
                         capture_output=True, text=True, timeout=60, check=False)
    assert run.returncode == 1
    assert "--socket" in run.stderr and str(path) in run.stderr
    assert path.read_text() == "keep me"


def test_a_socket_a_service_listens_on_is_not_taken(demo_library_path, tmp_path):
    path = str(tmp_path / "busy.sock")
    first = start(demo_library_path, "--socket", path)
    try:
        second = subprocess.run([os.environ["ECVPOSE_CLI"], "serve", "--db", str(demo_library_path), "--socket", path],
                                capture_output=True, text=True, timeout=60, check=False)
        assert second.returncode == 1 and "a service listening there" in second.stderr
        client = Client(path)  # the first service still answers
        assert len(client.ask(request(id=1))["detections"]) == 3
        client.close()
    finally:
        first.send_signal(signal.SIGTERM)
        first.communicate(timeout=60)
    assert first.returncode == 0
