"""A stranger on the network (issue 20): connects to a coupler's tcp
endpoints again and again and sends what could harm a run if it got through,
until told to stop. Used by test_coupler.py (coupler_stranger).

Each round, on each endpoint:
  * raw TCP: bytes of garbage, then the 80-byte RESULT forgery of issue 20
    (MPSC, version 1, type RESULT, all else zero) as plain bytes;
  * a ZeroMQ DEALER without security (NULL mechanism) sending the forgery
    and a well-formed RESULT with a made-up plate state;
  * a ZeroMQ DEALER with CURVE, the coupler's real server public key (as a
    stranger may learn it: it is public) but a key pair of its own.
None of these may reach the coupler's protocol loop."""
import os
import socket
import struct
import sys
import threading
import time

import numpy as np
import zmq

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', 'proto',
                                'python'))
import mpsproto  # noqa: E402

FORGED_RESULT = b'MPSC' + struct.pack('<HH', 1, 6) + bytes(72)  # the 80 bytes


def forged_frames():
    """A well-formed RESULT (solid STATE) with made-up particles: what a
    forger who knows the protocol would send."""
    n = 8
    m = mpsproto.Message(mpsproto.Type.RESULT, payload=mpsproto.Payload.STATE, step=3,
                         time=0.01, dt=1e-4, id=np.arange(n, dtype=np.int32),
                         x=np.random.rand(n, 2), v=np.random.rand(n, 2) * 100,
                         surface=np.ones(n, dtype=np.uint8), fixed=np.zeros(n, dtype=np.uint8))
    return mpsproto.encode(m)


class Stranger:
    def __init__(self, host, ports, server_public=None):
        self.host, self.ports, self.server_public = host, ports, server_public
        self.stop = threading.Event()
        self.attempts = {'raw': 0, 'null': 0, 'curve': 0}
        self.thread = threading.Thread(target=self._run, daemon=True)

    def start(self):
        self.thread.start()
        return self

    def finish(self):
        self.stop.set()
        self.thread.join(timeout=30)

    def _raw(self, port):
        try:
            with socket.create_connection((self.host, port), timeout=1.0) as s:
                s.sendall(os.urandom(64) + FORGED_RESULT * 4)
                s.settimeout(0.2)
                try:
                    s.recv(256)
                except OSError:
                    pass
            self.attempts['raw'] += 1
        except OSError:
            pass

    def _zmq(self, ctx, port, curve):
        s = ctx.socket(zmq.DEALER)
        s.setsockopt(zmq.LINGER, 0)
        s.setsockopt(zmq.SNDTIMEO, 200)
        if curve:
            pub, sec = zmq.curve_keypair()
            s.curve_serverkey = self.server_public
            s.curve_publickey = pub
            s.curve_secretkey = sec
        s.connect(f'tcp://{self.host}:{port}')
        for frames in ([FORGED_RESULT], forged_frames(), [b'garbage' * 20]):
            try:
                s.send_multipart(frames)
            except zmq.Again:
                pass  # never connected: that is the point
        time.sleep(0.15)
        s.close()
        self.attempts['curve' if curve else 'null'] += 1

    def _run(self):
        ctx = zmq.Context()
        while not self.stop.is_set():
            for port in self.ports:
                self._raw(port)
                self._zmq(ctx, port, False)
                if self.server_public:
                    self._zmq(ctx, port, True)
            time.sleep(0.05)
        ctx.term()
