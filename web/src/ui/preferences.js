// Per-browser preferences (localStorage; everything works without it).

function get(key, fallback) {
  try {
    const v = localStorage.getItem(key);
    return v === null ? fallback : JSON.parse(v);
  } catch {
    return fallback;
  }
}

function set(key, value) {
  try {
    localStorage.setItem(key, JSON.stringify(value));
  } catch {
    /* private mode etc. */
  }
}

export function displayName() {
  let name = get('devsurf.name', null);
  if (!name) {
    name = `guest-${Math.floor(Math.random() * 0xffff).toString(16).padStart(4, '0')}`;
    set('devsurf.name', name);
  }
  return name;
}

export function setDisplayName(name) {
  set('devsurf.name', String(name).slice(0, 40));
}

export function accessibility() {
  return !!get('devsurf.a11y', false);
}

export function setAccessibility(on) {
  set('devsurf.a11y', !!on);
}

/** Tokens we know for a session (from creating it or from the demo list). */
export function sessionTokens(id) {
  return get(`devsurf.tokens.${id}`, {});
}

export function rememberSessionTokens(id, tokens) {
  const known = sessionTokens(id);
  const merged = { ...known };
  if (tokens.edit) merged.edit = tokens.edit;
  if (tokens.view) merged.view = tokens.view;
  if (tokens.name) merged.name = tokens.name;
  if (tokens.opened) merged.opened = tokens.opened;
  set(`devsurf.tokens.${id}`, merged);
  return merged;
}

/**
 * The sessions this browser created or joined (opened in the editor), most recent first:
 * [{ id, name, edit, view, opened }] — demo sessions only listed on the start page are not among them.
 */
export function openedSessions() {
  const out = [];
  try {
    for (let i = 0; i < localStorage.length; i++) {
      const key = localStorage.key(i);
      if (!key || !key.startsWith('devsurf.tokens.')) continue;
      const entry = get(key, null);
      if (entry && entry.opened && (entry.edit || entry.view)) out.push({ id: key.slice('devsurf.tokens.'.length), ...entry });
    }
  } catch {
    /* no storage */
  }
  return out.sort((a, b) => b.opened - a.opened);
}

/** Forgets what this browser knows of a session (its tokens, name and when it was opened). */
export function forgetSession(id) {
  try {
    localStorage.removeItem(`devsurf.tokens.${id}`);
  } catch {
    /* ignore */
  }
}

export function apiKey() {
  try {
    return sessionStorage.getItem('devsurf.apiKey') || '';
  } catch {
    return '';
  }
}

export function setApiKey(key) {
  try {
    sessionStorage.setItem('devsurf.apiKey', key);
  } catch {
    /* ignore */
  }
}
