// Each robot its own colour, the same in every panel: its arrow on the top view and in 3-D, the
// ring of its candidates, its name in the candidate list and the mission panel. Colours go to
// robot ids in sorted order, so every page (and a reload) gives a robot the same colour. The
// palette avoids the candidate states' colours (proposed yellow, selected cyan, moving green,
// refused red).
const PALETTE = ['#ff7b29', '#c77dff', '#ff5fa2', '#5b8cff', '#e8e8e8', '#b08b5a', '#2ec4b6', '#ffd6a5'];

let known = [];

/** The robots the page knows of (any order); colours follow the sorted ids. */
export function setRobotIds(ids) {
  const next = [...new Set(ids.filter(Boolean))].sort();
  if (next.length === known.length && next.every((id, i) => id === known[i])) return false;
  known = next;
  return true;
}

/** CSS colour of robot `id` ('#rrggbb'). */
export function robotColor(id) {
  let i = known.indexOf(id);
  if (i < 0) i = known.length; // not yet known: the next free colour
  return PALETTE[i % PALETTE.length];
}

/** The same as a number (three.js colours). */
export function robotColorInt(id) {
  return parseInt(robotColor(id).slice(1), 16);
}
