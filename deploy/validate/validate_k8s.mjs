// Checks every object of a rendered manifest stream (stdin) against the Kubernetes schema of
// kubernetes-models (and the Prometheus operator's for ServiceMonitor). Exit 1 on any problem.
import { readFileSync } from "node:fs";
import yaml from "js-yaml";

const modules = {
  "v1": "kubernetes-models/v1",
  "apps/v1": "kubernetes-models/apps/v1",
  "autoscaling/v2": "kubernetes-models/autoscaling/v2",
  "policy/v1": "kubernetes-models/policy/v1",
  "networking.k8s.io/v1": "kubernetes-models/networking.k8s.io/v1",
  "monitoring.coreos.com/v1": "@kubernetes-models/prometheus-operator/monitoring.coreos.com/v1",
};

const docs = yaml.loadAll(readFileSync(0, "utf8")).filter((d) => d);
let failures = 0;
for (const doc of docs) {
  const name = `${doc.kind}/${doc.metadata?.name}`;
  const path = modules[doc.apiVersion];
  if (!path) {
    console.error(`${name}: apiVersion ${doc.apiVersion} has no schema here`);
    failures++;
    continue;
  }
  const Model = (await import(path))[doc.kind];
  if (!Model) {
    console.error(`${name}: unknown kind for ${doc.apiVersion}`);
    failures++;
    continue;
  }
  try {
    new Model(doc).validate();
    console.log(`ok ${doc.apiVersion} ${name}`);
  } catch (e) {
    console.error(`${name}: ${e.message}`);
    failures++;
  }
}
if (docs.length === 0) {
  console.error("no objects on stdin");
  process.exit(1);
}
process.exit(failures ? 1 : 0);
