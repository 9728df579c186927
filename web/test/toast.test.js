// Error toasts title the protocol's error codes in words (a new user's tryout read "invalid",
// "diverged" and "offline" as the titles). Every WebSocket error code docs/protocol.md lists has
// a title of its own: the list is read from the document, so a new code without one fails here.
import { describe, expect, it } from 'vitest';
import { readFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';
import { errorTitle } from '../src/ui/Toast.js';

const protocol = readFileSync(fileURLToPath(new URL('../../docs/protocol.md', import.meta.url)), 'utf8');

/** The backticked codes of the paragraph that starts "WebSocket: `{"type":"error"". */
function webSocketErrorCodes() {
  const start = protocol.indexOf('WebSocket: `{"type":"error"');
  const paragraph = protocol.slice(start, protocol.indexOf('\n\n', start));
  const codes = paragraph.slice(paragraph.indexOf('Codes:'));
  // The paragraph also names the message's fields and what an error's `path` may give.
  const fields = new Set(['path', 'params', 'op']);
  return [...codes.matchAll(/`([a-z_]+)`/g)].map((m) => m[1]).filter((word) => !fields.has(word));
}

describe('error toast titles', () => {
  it('reads the codes from the protocol document', () => {
    const codes = webSocketErrorCodes();
    expect(codes).toContain('invalid');
    expect(codes).toContain('diverged');
    expect(codes.length).toBeGreaterThan(15);
  });

  it('gives every WebSocket error code and the client\'s own "offline" a title in words', () => {
    for (const code of [...webSocketErrorCodes(), 'offline']) {
      const title = errorTitle(code);
      expect(title, code).not.toBe(code);
      expect(title, code).toMatch(/^[A-Z][a-z]/);
    }
  });

  it('keeps an unknown code as it is and titles a missing one "Error"', () => {
    expect(errorTitle('brand_new_code')).toBe('brand_new_code');
    expect(errorTitle(undefined)).toBe('Error');
  });
});
