// The WebSocket to hapticd's /ws (protocol/websocket.md): one JSON object per text message. The
// address is the page's own host (location.host), so the page works from any machine that can
// reach [web] listen. With a key, the hello carries HMAC-SHA512-256 of the server's nonce
// (WebCrypto: HMAC-SHA-512 cut to 32 bytes); WebCrypto exists only on https or localhost pages,
// so a page opened over plain http from another machine watches only.

function hexToBytes(hex) {
  const out = new Uint8Array(hex.length / 2);
  for (let i = 0; i < out.length; ++i) out[i] = parseInt(hex.substr(2 * i, 2), 16);
  return out;
}

async function tagOf(keyHex, nonceHex) {
  const key = await crypto.subtle.importKey('raw', hexToBytes(keyHex),
                                            { name: 'HMAC', hash: 'SHA-512' }, false, ['sign']);
  const mac = new Uint8Array(await crypto.subtle.sign('HMAC', key, hexToBytes(nonceHex)));
  return Array.from(mac.slice(0, 32), (b) => b.toString(16).padStart(2, '0')).join('');
}

export class Connection {
  // onMessage(message) for every message; onLink(text) when the link changes
  constructor(onMessage, onLink) {
    this.onMessage = onMessage;
    this.onLink = onLink;
    this.ws = null;
    this.keyHex = '';
  }

  open() {
    const scheme = location.protocol === 'https:' ? 'wss' : 'ws';
    this.ws = new WebSocket(`${scheme}://${location.host}/ws`);
    this.ws.onmessage = (ev) => this.receive(JSON.parse(ev.data));
    this.ws.onclose = () => {
      this.onLink('disconnected: retrying');
      setTimeout(() => this.open(), 1000);
    };
  }

  async receive(m) {
    if (m.type === 'hello') {
      const hello = { type: 'hello', name: 'viewer' };
      if (m.key_required && this.keyHex.length === 64 && globalThis.crypto?.subtle)
        hello.tag = await tagOf(this.keyHex, m.nonce);
      this.send(hello);
      return;
    }
    this.onMessage(m);
  }

  send(message) {
    if (this.ws && this.ws.readyState === WebSocket.OPEN) this.ws.send(JSON.stringify(message));
  }

  // a new key: reconnect so that the hello carries its tag
  setKey(keyHex) {
    this.keyHex = keyHex.trim();
    if (this.ws) this.ws.close();
  }
}
