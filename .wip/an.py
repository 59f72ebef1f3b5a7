import re,os,sys,collections,glob
root='/work/wt/h38p'
os.chdir(root)
pat=re.compile(r'^\s*pub (fn|struct|enum|const|static|type|trait|mod|use)\b(.*)')
items=[]
for dp,dn,fn in os.walk('src'):
    for f in fn:
        if not f.endswith('.rs'): continue
        p=os.path.join(dp,f)
        if p.startswith('src/cli/'): continue
        for i,l in enumerate(open(p),1):
            m=pat.match(l)
            if not m: continue
            kind,rest=m.groups()
            if kind=='use':
                names=re.findall(r'\b([A-Za-z_][A-Za-z0-9_]*)\b',rest.split('::')[-1]) if '{' not in rest else re.findall(r'([A-Za-z_][A-Za-z0-9_]*)\s*[,}]',rest)
                name=','.join(names) or rest.strip()
            else:
                mm=re.match(r'\s*(?:unsafe\s+)?(?:fn\s+)?([A-Za-z_][A-Za-z0-9_]*)',rest)
                name=mm.group(1) if mm else rest
            items.append((p,i,kind,name,l.rstrip()))
outside=[]
for g in ['tests/**/*.rs','benches/**/*.rs','examples/**/*.rs','python/src/**/*.rs','src/main.rs']:
    outside+=glob.glob(g,recursive=True)
tok=collections.defaultdict(set)
for f in outside:
    for t in set(re.findall(r'[A-Za-z_][A-Za-z0-9_]*',open(f).read())):
        tok[t].add(f)
out=[]
for p,i,kind,name,l in items:
    users=set()
    for n in name.split(','):
        users|=tok.get(n,set())
    out.append((p,i,kind,name,sorted(users)))
import json
json.dump(out,open('/tmp/h38p/items.json','w'))
cls=collections.Counter()
for p,i,k,n,u in out:
    nt=[x for x in u if not x.startswith('tests/')]
    if not u: c='none'
    elif not nt: c='tests-only'
    else: c='nontest'
    cls[c]+=1
print(cls)
