// The page's keys (`?`, Space, c, Delete, Ctrl+Z, f, t, 1 3 7 0, x y z …) act wherever the focus
// is, except while typing in a text field: a checkbox, button, slider or list just clicked keeps
// no key for itself (the handlers call preventDefault, so Space does not also press the button
// and a letter does not pick an item of a focused list).

// Input types that take no typed text.
const NOT_TYPED = new Set(['checkbox', 'radio', 'range', 'button', 'submit', 'reset', 'file', 'color', 'image']);

// Whether `target` (a key event's) is a field the user types text into.
export function typingIn(target) {
  if (target instanceof HTMLInputElement) return !NOT_TYPED.has(target.type);
  return target instanceof HTMLTextAreaElement || !!target?.isContentEditable;
}
