// One gesture's requests (a drag, a slider, the timeline): at most one is in flight, and while
// it is, only the newest value waits — never a queue. A value is a function that makes the
// request's body when it is sent, so it can use the newest scene (a drag by offsets does).

export class Channel {
  // `send(body)` returns a promise of a frame; `done(frame, t)` shows it (t: the time of the
  // pointer event that asked for it); `fail(error)` reports a refusal.
  constructor(send, done, fail, counters) {
    this.send = send;
    this.done = done;
    this.fail = fail;
    this.counters = counters || { sent: 0, coalesced: 0 };
    this.pending = null;
    this.inflight = false;
  }

  push(makeBody, t = performance.now()) {
    if (this.pending) this.counters.coalesced += 1;
    this.pending = { makeBody, t };
    this.pump();
  }

  pump() {
    if (this.inflight || !this.pending) return;
    const { makeBody, t } = this.pending;
    this.pending = null;
    const body = makeBody();
    if (body === null) return this.pump();
    this.inflight = true;
    this.counters.sent += 1;
    this.send(body)
      .then((frame) => this.done(frame, t))
      .catch((e) => this.fail(e))
      .finally(() => {
        this.inflight = false;
        this.pump();
      });
  }

  get idle() {
    return !this.inflight && !this.pending;
  }
}

// The pointer event gestures follow: Chromium's pointerrawupdate where the page has it (a secure
// context, such as loopback) comes as the input arrives, where pointermove waits for the next
// animation frame (up to 16.7 ms at 60 Hz) before a request could leave.
export const MOVE_EVENT = 'onpointerrawupdate' in window ? 'pointerrawupdate' : 'pointermove';
