import re,os,sys,json,subprocess
root='/work/wt/h38p'; os.chdir(root)
pat=re.compile(r'^(\s*)pub (fn|struct|enum|const|static|type|trait|mod|use)\b')
AVOID=('src/topography/','src/brdf/map_two_scale.rs','src/brdf/topography.rs','src/recipe/topography.rs','src/instrument/plan/','src/optics/kirchhoff.rs','src/lib.rs','src/api.rs','src/cli/','src/main.rs')
_C=None
HEADTXT={}
def candidates():
    global _C
    if _C is not None: return _C
    out=[]
    for dp,dn,fn in os.walk('src'):
        for f in fn:
            if not f.endswith('.rs'): continue
            p=os.path.join(dp,f)
            if p.startswith(AVOID): continue
            txt=subprocess.run(['git','show','HEAD:'+p],capture_output=True,text=True).stdout
            HEADTXT[p]=txt.split('\n')
            for i,l in enumerate(txt.split('\n'),1):
                m=pat.match(l)
                if not m: continue
                if p.startswith('src/report/') and re.match(r'\s*pub (struct|enum) \w*(Doc|Output)\b',l): continue
                out.append((p,i))
    _C=out
    return out
def usetext(c):
    L=HEADTXT[c[0]]; i=c[1]-1; t=''
    while i<len(L):
        t+=L[i]
        if ';' in L[i]: break
        i+=1
    return t
def apply(keep):
    # keep: set of (p,i) to leave pub; narrow all other candidates
    byfile={}
    for p,i in candidates():
        if (p,i) in keep: continue
        byfile.setdefault(p,[]).append(i)
    for p,ls in byfile.items():
        L=open(p).read().split('\n')
        for i in ls:
            L[i-1]=pat.sub(lambda m:m.group(1)+'pub(crate) '+m.group(2),L[i-1],count=1)
        open(p,'w').write('\n'.join(L))
cmd=sys.argv[1]
if cmd=='apply':
    keep=set(tuple(x) for x in json.load(open('/tmp/h38p/keep.json'))) if os.path.exists('/tmp/h38p/keep.json') else set()
    subprocess.run(['git','checkout','--','src'],check=True)
    apply(keep)
elif cmd=='parse':
    keep=set(tuple(x) for x in json.load(open('/tmp/h38p/keep.json'))) if os.path.exists('/tmp/h38p/keep.json') else set()
    cands=set(candidates())
    new={}
    for fn in sys.argv[2:]:
        for line in open(fn):
            try: m=json.loads(line)
            except: continue
            if m.get('reason')!='compiler-message': continue
            msg=m['message']
            if msg['level'] not in ('error','warning'): continue
            tgt=m['target']['name']+':'+','.join(m['target']['kind'])
            code=(msg.get('code') or {}).get('code')
            def walk(mm):
                for s in mm['spans']: yield s
                for c in mm['children']: yield from walk(c)
            spans=list(walk(msg))
            if msg['level']=='warning' and code not in ('private_interfaces','private_bounds'): continue
            hits=[]
            mt=re.match(r'type `([\w:]+)` is private',msg['message'])
            if mt:
                segs=mt.group(1).split('::'); name=segs[-1]
                defs=[c for c in cands if re.search(r'pub (struct|enum|type|trait) '+name+r'\b',HEADTXT[c[0]][c[1]-1])]
                if len(defs)>1:
                    defs=[d for d in defs if all(sg in d[0] for sg in segs[1:-1][-1:])] or defs
                hits+=[d for d in defs if d not in keep]
            if code in ('E0364','E0365'):
                name=re.match(r'`(\w+)`',msg['message']).group(1)
                src_line=spans[0]['text'][0]['text'] if spans and spans[0]['text'] else ''
                path=re.search(r'use\s+([\w:]+)',src_line)
                defs=[c for c in cands if re.search(r'pub (fn|struct|enum|const|static|type|trait|mod) '+name+r'\b',HEADTXT[c[0]][c[1]-1])]
                if len(defs)>1 and path:
                    segs=[x for x in path.group(1).split('::') if x not in ('crate','super','self')]
                    defs=[d for d in defs if any(sg in d[0] for sg in segs)] or defs
                defs+=[c for c in cands if re.match(r'\s*pub use ',HEADTXT[c[0]][c[1]-1]) and re.search(r'\b'+name+r'\b',usetext(c))]
                defs=[d for d in defs if d not in keep]
                hits+=defs
            for s in spans:
                p=s['file_name']
                for ln in range(s['line_start'],s['line_end']+1):
                    if (p,ln) in cands and (p,ln) not in keep: hits.append((p,ln)); break
            if msg['level']=='warning':
                # keep the less-visible item (non-primary)
                hits=[h for h,s in zip(hits,spans) ] 
                hits=[]
                for s in [s for c in msg['children'] for s in c['spans']]:
                    p=s['file_name']
                    for ln in range(s['line_start'],s['line_end']+1):
                        if (p,ln) in cands: hits.append((p,ln)); break
            for h in hits: new.setdefault(h,set()).add(tgt+' '+(code or '')+' '+msg['message'][:80])
    R=json.load(open('/tmp/h38p/reasons.json')) if os.path.exists('/tmp/h38p/reasons.json') else {}
    for h,v in sorted(new.items()):
        print(h, sorted(v)[:3])
        R.setdefault(h[0]+':'+str(h[1]),[]).extend(sorted(v))
    json.dump(R,open('/tmp/h38p/reasons.json','w'),indent=0)
    keep|=set(new)
    json.dump(sorted(keep),open('/tmp/h38p/keep.json','w'))
    print('new',len(new),'keep',len(keep),'cands',len(cands))
