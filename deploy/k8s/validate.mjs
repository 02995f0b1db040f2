// deploy/k8s/validate.mjs — schema validation of the manifests against the Kubernetes API's
// OpenAPI schemas bundled in the npm package kubernetes-models (types, required fields; not
// unknown fields). Optional, outside `make test` (npm, not Debian); deploy/check.sh runs it
// when KUBERNETES_MODELS_DIR names a node_modules with the two packages:
//   npm install --prefix /tmp/k8sval kubernetes-models@5.1.0 js-yaml@4
//   KUBERNETES_MODELS_DIR=/tmp/k8sval/node_modules node deploy/k8s/validate.mjs deploy/k8s/*.yaml
import fs from 'fs';
import path from 'path';
import { pathToFileURL } from 'url';

// By file path: the package's "exports" map hides its subpaths from a bare import outside it.
const dir = path.resolve(process.env.KUBERNETES_MODELS_DIR || 'node_modules');
const load = (rel) => import(pathToFileURL(path.join(dir, rel)).href);
const yaml = await load('js-yaml/dist/js-yaml.mjs');
const { ConfigMap } = await load('kubernetes-models/v1/ConfigMap.js');
const { Service } = await load('kubernetes-models/v1/Service.js');
const { Deployment } = await load('kubernetes-models/apps/v1/Deployment.js');
const { HorizontalPodAutoscaler } = await load('kubernetes-models/autoscaling/v2/HorizontalPodAutoscaler.js');
const { PodDisruptionBudget } = await load('kubernetes-models/policy/v1/PodDisruptionBudget.js');
const { Job } = await load('kubernetes-models/batch/v1/Job.js');
const kinds = { ConfigMap, Service, Deployment, HorizontalPodAutoscaler, PodDisruptionBudget, Job };

let pass = 0, fail = 0;
for (const f of process.argv.slice(2)) {
  for (const doc of yaml.loadAll(fs.readFileSync(f, 'utf8'))) {
    if (!doc || !kinds[doc.kind]) continue; // Kustomization: no schema in the package
    try {
      new kinds[doc.kind](doc).validate();
      pass++;
      console.log(`ok - schema ${path.basename(f)} ${doc.kind}/${doc.metadata.name}`);
    } catch (e) {
      fail++;
      console.log(`FAIL - schema ${path.basename(f)} ${doc.kind}: ${e.message}`);
    }
  }
}
// The validator must reject a Deployment without a selector (it is not a no-op).
try {
  new Deployment({ metadata: { name: 'x' }, spec: { template: {} } }).validate();
  fail++;
  console.log('FAIL - schema validator accepted a Deployment without a selector');
} catch (e) {
  pass++;
  console.log('ok - schema validator rejects a Deployment without a selector');
}
console.log(`${pass} passed, ${fail} failed`);
process.exit(fail ? 1 : 0);
