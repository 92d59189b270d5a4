// The Robot tab's connect form: the link (a serial URL, the robot's radio address) and the
// tracker, either ParkourLab's own datagrams (pkt1) or a NatNet stream (OptiTrack Motive), whose
// fields show only when NatNet is chosen. Numbers are checked against RobotConnect's own ranges
// (fields.js) before anything is sent; a 422 lands at its field.
import { Fields } from "./fields.js";
import { $, say, call, on } from "./api.js";
import { showStatus } from "./robot.js";

const NATNET_NUMBERS = [{ name: "natnet_rigid_body_id", rule: "RobotConnect.natnet_rigid_body_id" },
  { name: "natnet_command_port", rule: "RobotConnect.natnet_command_port" }];
const NATNET_TEXTS = ["natnet_version", "natnet_server_host"];
// Every field the service may refuse, by its body location (each input is named as its property).
const LOCATIONS = Object.fromEntries(["url", "robot_address", "tracker_port", "tracker_protocol", ...NATNET_TEXTS,
  "natnet_multicast_group", ...NATNET_NUMBERS.map((f) => f.name)].map((name) => [name, name]));

const natnetChosen = () => $("#tracker-protocol").value === "natnet";

function showProtocol() {
  const natnet = natnetChosen();
  $("#natnet-fields").hidden = !natnet;
  $("#natnet-help").hidden = !natnet;
  $("#natnet-fields").disabled = !natnet;  // hidden fields are neither checked nor sent
}
on("#tracker-protocol", "change", showProtocol);
showProtocol();

// The request body, or null once the bad numbers are marked (nothing is sent then).
async function connectBody(form) {
  const natnet = natnetChosen();
  const numbers = await Fields.readFields(form, [{ name: "tracker_port", rule: "RobotConnect.tracker_port" },
    ...(natnet ? NATNET_NUMBERS : [])]);
  if (!numbers) return null;  // an empty or non-numeric number is marked at its field, never sent as 0
  const text = (name) => String(form.elements[name].value).trim();
  const body = { url: text("url"), robot_address: text("robot_address"), ...numbers, tracker_protocol: natnet ? "natnet" : "pkt1" };
  if (natnet) {
    for (const name of NATNET_TEXTS) body[name] = text(name);
    body.natnet_multicast_group = text("natnet_multicast_group") || null;  // empty: unicast
  }
  return body;
}

on("#connect-form", "submit", async (event) => {
  event.preventDefault();
  const body = await connectBody(event.target);
  if (!body) return;
  const status = await call("POST", "/robot/connect", body, { form: event.target, locations: LOCATIONS });
  showStatus(status);
  const tracker = body.tracker_protocol === "natnet" ? `, NatNet rigid body ${body.natnet_rigid_body_id}` : "";
  say(`Connected to ${status.robot_address ?? body.robot_address} on ${status.url ?? body.url}${tracker}.`);
});
