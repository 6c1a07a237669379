#!/usr/bin/python3
"""A solver that speaks protocol version 1 (before implicit coupling): the
coupler must refuse it with a clear REJECT. Writes what it was told to REPORT (argv[1]) and exits 0 if it
got a REJECT. Usage: bad_version_solver.py REPORT --connect ENDPOINT"""
import os, struct, sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', 'proto', 'python'))
import mpsproto  # noqa: E402
import zmq  # noqa: E402

report = sys.argv[1]
endpoint = sys.argv[sys.argv.index('--connect') + 1]
ctx = zmq.Context()
sock = mpsproto.connect(ctx, endpoint)
frames = mpsproto.encode(mpsproto.Message(type=mpsproto.Type.HELLO,
                                          text=f"role=solid model=v1 pid={os.getpid()}"))
header = bytearray(frames[0])
struct.pack_into('<H', header, 4, 1)  # version 1
sock.send_multipart([bytes(header)] + frames[1:])
try:
    m = mpsproto.recv(sock, 20000)
    with open(report, 'w') as f:
        f.write(f"{mpsproto.Type(m.type).name}: {m.text}\n")
    ok = m.type == mpsproto.Type.REJECT
except Exception as e:  # noqa: BLE001
    with open(report, 'w') as f:
        f.write(f"no answer: {e}\n")
    ok = False
sock.close(0)
ctx.term()
sys.exit(0 if ok else 1)
